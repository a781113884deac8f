"""The cobot page in a real browser: an engineer powers a powered-off cobot on.

The cobot is a simulated gateway process in its boot state (powered off, no
program); the server is a separate process (live_url), which reaches it over
OPC UA as it would a plant's.
"""

from collections.abc import Callable, Iterator
from pathlib import Path

import pytest
from django.contrib.auth.models import User
from playwright.sync_api import Page, expect

from hrc.cobots.models import CobotCommand, Device
from hrc.cobots.simulated import GatewayProcess
from hrc.organisations.models import Organisation
from hrc_gateway import urua
from tests import factories

pytestmark = pytest.mark.django_db(transaction=True)

SignIn = Callable[[Page, User], None]
Screenshot = Callable[[Page, str], Path]


@pytest.fixture
def gateway(tmp_path: Path) -> Iterator[GatewayProcess]:
    process = GatewayProcess("cobot1", tmp_path / "cobot1.json").start()
    yield process
    process.stop()


def test_an_engineer_powers_a_cobot_on_through_the_confirmation_dialog(
    page: Page,
    live_url: str,
    sign_in: SignIn,
    screenshot: Screenshot,
    engineer: User,
    organisation: Organisation,
    gateway: GatewayProcess,
) -> None:
    cobot = factories.make_cobot(organisation, name="cobot1", endpoint=gateway.endpoint)
    sign_in(page, engineer)
    page.goto(f"{live_url}/cobots/")
    page.get_by_role("link", name="cobot1").click()
    state = page.locator('#state [data-field="RobotMode"]')
    expect(state).to_have_text(urua.ROBOT_MODE_POWER_OFF)

    page.get_by_role("button", name="Power on").click()
    dialog = page.get_by_role("dialog")
    expect(dialog).to_contain_text("Power on cobot1?")
    assert not CobotCommand.objects.exists()  # nothing goes out before the confirmation
    dialog.get_by_role("button", name="Confirm").click()

    expect(page.locator("#outcome")).to_have_text("Power on: cobot1 done.", timeout=20_000)
    expect(state).to_have_text(urua.ROBOT_MODE_RUNNING)
    newest = page.locator("#commands tbody tr").first
    expect(newest).to_contain_text(engineer.username)
    expect(newest).to_contain_text("Power on")
    expect(newest).to_contain_text("Done")
    screenshot(page, "cobot-powered-on")
    record = CobotCommand.objects.get()
    assert (record.cobot_id, record.requested_by, record.outcome) == (cobot.pk, engineer, "ok")


def test_a_cancelled_confirmation_sends_nothing(
    page: Page,
    live_url: str,
    sign_in: SignIn,
    engineer: User,
    organisation: Organisation,
    gateway: GatewayProcess,
) -> None:
    cobot = factories.make_cobot(organisation, name="cobot1", endpoint=gateway.endpoint)
    sign_in(page, engineer)
    page.goto(f"{live_url}/cobots/{cobot.pk}/")

    page.get_by_role("button", name="Power off").click()
    page.get_by_role("dialog").get_by_role("button", name="Cancel").click()

    expect(page.get_by_role("dialog")).to_be_hidden()
    page.wait_for_timeout(500)
    assert not CobotCommand.objects.exists()
    expect(page.locator("#commands tbody")).to_contain_text("No commands yet.")


def test_an_admin_registers_a_device_of_a_cell_and_deactivates_it(
    page: Page,
    live_url: str,
    sign_in: SignIn,
    screenshot: Screenshot,
    admin: User,
    organisation: Organisation,
    gateway: GatewayProcess,
) -> None:
    cobot = factories.make_cobot(organisation, name="cobot1", endpoint=gateway.endpoint, cell="A")
    sign_in(page, admin)
    page.goto(f"{live_url}/cobots/")
    page.get_by_role("link", name="Devices").click()
    page.get_by_role("link", name="Register a device").click()
    page.get_by_label("Name").fill("axis1")
    page.get_by_label("Kind").select_option("linear-axis")
    page.get_by_label("Cell").select_option("A")
    page.get_by_label("Gateway").select_option(str(cobot.pk))
    page.get_by_role("button", name="Register the device").click()

    row = page.locator("table.devices tbody tr", has_text="axis1")
    expect(row).to_contain_text("Linear axis")
    expect(row).to_contain_text("cobot1")
    screenshot(page, "device-list")
    device = Device.objects.get(organisation=organisation, name="axis1")
    assert (device.kind, device.cell, device.gateway_id) == ("linear-axis", "A", cobot.pk)

    row.get_by_role("link", name="axis1").click()
    page.get_by_label("Active").uncheck()
    page.get_by_role("button", name="Save").click()
    expect(page.locator("table.devices tbody tr", has_text="axis1")).to_contain_text(
        "out of service"
    )
    device.refresh_from_db()
    assert device.is_active is False
