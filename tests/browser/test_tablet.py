"""The operator tablet in a real browser, against real parts: a Celery worker on a private broker,
a simulated cobot (an OPC UA gateway process), the cobot monitor, and daphne serving the page
and its socket. Screenshots of each state go to var/screenshots/."""

from __future__ import annotations

import re
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pytest
from django.contrib.auth.models import User
from playwright.sync_api import Browser, BrowserContext, Page, ViewportSize, expect

from hrc.cases import services as case_services
from hrc.cases.choices import CaseStatus, EventType, JobState
from hrc.cases.models import Case, Job, WorkItem
from hrc.cobots.drivers.runner import SyncDriver, driver_for
from hrc.cobots.simulated import GatewayProcess
from hrc.live import groups
from hrc.organisations import services as organisation_services
from hrc.organisations.choices import Role
from hrc.organisations.models import Membership, Organisation
from hrc.patterns.models import PatternVersion
from hrc_gateway import urua
from tests import factories
from tests.browser.conftest import assert_fits
from tests.cases.patterns import PICK, PROGRAM, shared_space
from tests.live.server import LiveServer, MonitorProcess
from tests.support.polling import until
from tests.support.workers import RedisProcess, WorkerProcess

pytestmark = pytest.mark.django_db(transaction=True)

Screenshot = Callable[[Page, str], Path]
PORTRAIT = ViewportSize(width=800, height=1280)
SMALL = ViewportSize(width=1024, height=768)
# A change shown within this many milliseconds, with no reload, came over the socket.
LIVE_MS = 30_000

CHECK_FORM: dict[str, Any] = {
    "type": "object",
    "required": ["parts", "clean"],
    "properties": {
        "parts": {"type": "integer", "minimum": 1, "title": "Parts in the tray"},
        "clean": {"type": "boolean", "title": "Tray is clean"},
        "remark": {"type": "string", "title": "Remark"},
    },
}


def _pick_check_place() -> dict[str, Any]:
    """The cobot picks (tc1); the operator checks the tray (to1, a form); the cobot picks again (tc2)."""
    step = {"step": {"program": PROGRAM, "number": PICK}, "timeout": 30}
    return {
        "format": "hrc-pattern/1",
        "name": "Pick, check, pick",
        "actors": [{"id": "c", "type": "cobot", "program": PROGRAM}, {"id": "o", "type": "operator"}],
        "processes": [{
            "id": "N", "workpiece": "w", "actors": ["c", "o"],
            "places": [{"id": "p0", "tokens": 1}, {"id": "p1"}, {"id": "p2"}, {"id": "p3"}],
            "transitions": [
                {"id": "tc1", "performer": "c", "label": "first pick", "task": step},
                {"id": "to1", "performer": "o", "label": "Check the tray", "task": {
                    "instructions": "Count the parts and look for chips.", "form": CHECK_FORM}},
                {"id": "tc2", "performer": "c", "label": "second pick", "task": step},
            ],
            "arcs": [["p0", "tc1"], ["tc1", "p1"], ["p1", "to1"], ["to1", "p2"],
                     ["p2", "tc2"], ["tc2", "p3"]],
        }],
        "constraints": [],
    }  # fmt: skip


def _sign_in(page: Page, url: str, user: User) -> None:
    page.goto(f"{url}/accounts/login/")
    page.get_by_label("User name").fill(user.get_username())
    page.get_by_label("Password").fill(factories.PASSWORD)
    page.get_by_role("button", name="Sign in").click()
    # Where each role lands: operators at the tablet, the others at the start page.
    page.wait_for_url(lambda landed: landed.startswith(url) and "/accounts/login/" not in landed)


# The cell: a gateway, a worker, the monitor, a server, all on a private broker ----------------


@pytest.fixture
def gateway(tmp_path: Path) -> Iterator[GatewayProcess]:
    process = GatewayProcess("cellarm", tmp_path / "cellarm.json", time_scale=0.5).start()
    driver = driver_for("cellarm", process.endpoint, step_timeout=30.0)
    driver.call("PowerOn", timeout=30)
    driver.call("SelectProgram", PROGRAM)
    driver.call("StartProgram")
    yield process
    driver.close()
    process.stop()


@pytest.fixture
def arm(gateway: GatewayProcess) -> SyncDriver:
    return driver_for("cellarm", gateway.endpoint)


@dataclass
class Cell:
    server: LiveServer
    monitor: MonitorProcess  # started by the test, once its cobots exist


@pytest.fixture
def cell(
    broker: RedisProcess,
    start_worker: Callable[..., WorkerProcess],
    tmp_path: Path,
    settings: Any,
) -> Iterator[Cell]:
    """A server, a worker (with the sweeper) and the monitor on the test's broker; this process's
    broadcasts go through the same channel layer."""
    from channels.layers import channel_layers

    layer = settings.CHANNEL_LAYERS["default"]
    settings.CHANNEL_LAYERS = {
        "default": {**layer, "CONFIG": {**layer["CONFIG"], "hosts": [broker.url]}}
    }
    channel_layers.backends.clear()
    start_worker(beat=True)
    environment = {"REDIS_URL": broker.url, "HRC_SWEEP_SECONDS": "0.5"}
    server = LiveServer(tmp_path / "server.log", environment).start()
    monitor = MonitorProcess(tmp_path / "monitor.log", environment)
    try:
        yield Cell(server, monitor)
    finally:
        monitor.stop()
        server.stop()
        groups.flush()
        channel_layers.backends.clear()


@pytest.fixture
def version(organisation: Organisation, engineer: User) -> PatternVersion:
    return factories.make_version(organisation, published_by=engineer, draft=_pick_check_place())


@pytest.fixture
def tablet(browser: Browser) -> Iterator[BrowserContext]:
    context = browser.new_context(viewport=ViewportSize(width=1280, height=800), has_touch=True)
    yield context
    context.close()


def test_an_operator_sees_the_task_appear_completes_it_and_the_cobot_goes_on(
    cell: Cell,
    tablet: BrowserContext,
    browser: Browser,
    version: PatternVersion,
    organisation: Organisation,
    operator: User,
    outsider: User,
    engineer: User,
    gateway: GatewayProcess,
    arm: SyncDriver,
    screenshot: Screenshot,
) -> None:
    # In cell A: a STOP names the cell it stops (the whole floor's tablet has none to stop).
    cobot = factories.make_cobot(organisation, name="cellarm", endpoint=gateway.endpoint, cell="A")
    cell.monitor.start()
    url = cell.server.url
    page = tablet.new_page()
    _sign_in(page, url, operator)
    page.goto(f"{url}/tablet/A/")
    expect(page.locator(".connection")).to_have_text("Live")
    expect(page.locator(f'.cobot[data-cobot="{cobot.pk}"] dd.mode')).to_have_text(
        "Running", timeout=LIVE_MS
    )

    # Someone of another organisation has a tablet open too.
    elsewhere = browser.new_context(viewport=ViewportSize(width=1280, height=800), has_touch=True)
    outsider_page = elsewhere.new_page()
    _sign_in(outsider_page, url, outsider)
    outsider_page.goto(f"{url}/tablet/")
    expect(outsider_page.locator(".connection")).to_have_text("Live")

    case = case_services.start_case(
        version, started_by=engineer,
        actor_mapping={"o": {"users": [operator.pk]}, "c": {"cobot": cobot.pk}},
    )  # fmt: skip
    card = page.locator(".cards.mine .card", has_text="Check the tray")
    expect(card).to_be_visible(timeout=LIVE_MS)  # the worker's cobot finished tc1; no reload
    expect(card.locator(".with-cobots")).to_contain_text("cellarm")
    screenshot(page, "tablet-task-appeared")

    card.get_by_role("button", name="Start").click()
    expect(card).to_have_attribute("data-state", "running")
    card.get_by_role("button", name="Complete…").click()
    dialog = page.locator(".form-dialog")
    expect(dialog.get_by_label("Parts in the tray *")).to_be_visible()
    # A yes/no is two choices, neither chosen: nothing is answered for the operator.
    clean = dialog.get_by_role("group", name="Tray is clean *")
    expect(clean.get_by_role("radio")).to_have_count(2)
    expect(clean.get_by_label("Yes")).not_to_be_checked()
    expect(clean.get_by_label("No")).not_to_be_checked()
    expect(dialog.locator('input[type="checkbox"]')).to_have_count(0)
    dialog.get_by_label("Parts in the tray *").fill("12")
    dialog.get_by_role("button", name="Complete").click()  # "clean" unanswered: refused here
    expect(dialog.locator('[data-field="clean"] .field-error')).to_have_text(
        "an answer is required"
    )
    expect(dialog.locator('[data-field="parts"] .field-error')).to_be_hidden()
    screenshot(page, "tablet-form-refused")
    assert_fits(page)
    assert WorkItem.objects.get(case=case, task="to1").state == "running"  # nothing was sent
    clean.get_by_label("No").check()
    expect(dialog.locator('[data-field="clean"] .field-error')).to_be_hidden()
    screenshot(page, "tablet-form")
    dialog.get_by_role("button", name="Complete").click()
    expect(card).to_have_count(0, timeout=LIVE_MS)
    # The cobot starts the next step, on the panel and on the cobot.
    expect(page.locator(f'.cobot[data-cobot="{cobot.pk}"] .doing')).to_contain_text(
        "second pick", timeout=LIVE_MS
    )
    screenshot(page, "tablet-cobot-next-step")
    until(lambda: Case.objects.get(pk=case.pk).status == CaseStatus.COMPLETED, timeout=60)
    item = WorkItem.objects.get(case=case, task="to1")
    assert item.result == {"parts": 12, "clean": False}  # the answers, and no empty remark
    assert item.completed_by == operator
    assert Job.objects.filter(case=case, state=JobState.SUCCEEDED).count() == 2

    # The other organisation's tablet saw none of it.
    expect(outsider_page.locator(".card")).to_have_count(0)
    assert outsider_page.evaluate("window.hrcTablet.store.state.cases.size") == 0
    assert outsider_page.evaluate("window.hrcTablet.store.state.cobots.size") == 0
    screenshot(outsider_page, "tablet-outsider")
    refused = outsider_page.goto(f"{url}/tablet/?organisation={organisation.pk}")
    assert refused is not None
    assert refused.status == 403
    elsewhere.close()

    # STOP pauses the cell; only a confirmed resume restarts it.
    page.get_by_role("button", name="STOP every cobot of the cell").click()
    expect(page.locator(".stop-banner")).to_contain_text(f"STOPPED by {operator.username}")
    until(lambda: arm.read(urua.STATE_PROGRAM_STATE) == urua.PROGRAM_PAUSED)
    page.get_by_role("button", name="Resume…").click()
    confirm = page.locator(".confirm-dialog")
    expect(confirm).to_be_visible()
    screenshot(page, "tablet-stopped-confirm-resume")
    confirm.get_by_role("button", name="Cancel").click()
    expect(page.locator(".stop-banner")).to_be_visible()
    assert arm.read(urua.STATE_PROGRAM_STATE) == urua.PROGRAM_PAUSED
    page.get_by_role("button", name="Resume…").click()
    confirm.get_by_role("button", name="Resume the cell").click()
    expect(page.locator(".stop-banner")).to_be_hidden(timeout=LIVE_MS)
    until(lambda: arm.read(urua.STATE_PROGRAM_STATE) == urua.PROGRAM_PLAYING)


# Losing the socket ------------------------------------------------------------------------


@pytest.fixture
def server(tmp_path: Path, transactional_db: None) -> Iterator[LiveServer]:
    running = LiveServer(tmp_path / "server.log").start()
    yield running
    running.stop()


def test_a_tablet_that_loses_its_socket_catches_up_after_reconnecting(
    server: LiveServer,
    tablet: BrowserContext,
    operator: User,
    choice_case: Case,
    screenshot: Screenshot,
) -> None:
    page = tablet.new_page()
    _sign_in(page, server.url, operator)
    page.goto(f"{server.url}/tablet/")
    card = page.locator(".cards.mine .card")
    expect(card).to_have_count(1)
    expect(card).to_have_attribute("data-state", "offered")

    server.stop()  # the socket is gone; the page stays
    expect(page.locator(".connection")).to_contain_text("reconnecting")
    screenshot(page, "tablet-reconnecting")
    # Meanwhile the operator's task moves on, and a new case offers another.
    [count] = WorkItem.objects.filter(case=choice_case)
    case_services.start_work_item(count, user=operator)
    case_services.start_case(
        choice_case.version, started_by=None, actor_mapping={"o": {"users": [operator.pk]}}
    )
    groups.flush()

    server.start()
    expect(page.locator(".connection")).to_have_text("Live", timeout=LIVE_MS)
    expect(page.locator(f'.card[data-item="{count.pk}"]')).to_have_attribute(
        "data-state", "running"
    )
    expect(card).to_have_count(2)
    assert page.evaluate("window.hrcTablet.socket.attempts") == 0


def test_the_tablet_fits_a_ten_inch_tablet_both_ways(
    server: LiveServer,
    tablet: BrowserContext,
    operator: User,
    organisation: Organisation,
    choice_case: Case,
    screenshot: Screenshot,
) -> None:
    factories.make_cobot(organisation, name="cobot1", cell="A")
    page = tablet.new_page()
    _sign_in(page, server.url, operator)
    page.goto(f"{server.url}/tablet/A/")
    expect(page.locator(".connection")).to_have_text("Live")
    expect(page.locator(".cards.mine .card")).to_have_count(1)
    screenshot(page, "tablet-landscape")
    assert_fits(page)
    for button in page.locator("button:visible").all():
        box = button.bounding_box()
        assert box is not None
        assert box["height"] >= 48, button.inner_text()
        assert box["width"] >= 48, button.inner_text()
    page.set_viewport_size(SMALL)
    screenshot(page, "tablet-1024x768")
    assert_fits(page)
    page.set_viewport_size(PORTRAIT)
    card = page.locator(".cards.mine .card")
    assert card.bounding_box()["width"] > 600  # type: ignore[index]  # one column, full width
    expect(page.locator(".cobot")).to_be_visible()
    screenshot(page, "tablet-portrait")
    assert page.evaluate("document.documentElement.scrollWidth") <= PORTRAIT["width"]
    assert re.search(r"Cell A", page.locator("header.site").inner_text())


def test_a_cells_tablet_offers_that_cells_tasks_and_says_how_many_wait_at_which_cells(
    server: LiveServer,
    tablet: BrowserContext,
    operator: User,
    organisation: Organisation,
    engineer: User,
    screenshot: Screenshot,
) -> None:
    version = factories.make_version(organisation, published_by=engineer, draft=shared_space())
    weld = factories.make_cobot(organisation, name="weld-arm", cell="weld")
    paint = factories.make_cobot(organisation, name="paint-arm", cell="paint")

    def start(cobot: Any) -> WorkItem:
        mapping = {"c": {"cobot": cobot.pk}, "o": {"users": [operator.pk]}}
        case = case_services.start_case(version, started_by=None, actor_mapping=mapping)
        return factories.open_work_item(case, "to1")

    at_weld, at_paint = start(weld), start(paint)
    page = tablet.new_page()
    _sign_in(page, server.url, operator)
    page.goto(f"{server.url}/tablet/weld/")
    expect(page.locator(".connection")).to_have_text("Live")
    cards = page.locator(".cards.mine .card")
    expect(cards).to_have_count(1)
    expect(cards).to_have_attribute("data-item", str(at_weld.pk))
    expect(page.locator(".elsewhere")).to_have_text("1 more task waits for you at the paint cell.")
    screenshot(page, "tablet-cell-scoped")

    # Live, no reload: a new case at the paint cell only adds to the count; the operator's
    # paint task, once started from the floor, is theirs here too.
    start(paint)
    groups.flush()
    expect(page.locator(".elsewhere")).to_have_text("2 more tasks wait for you at the paint cell.")
    expect(cards).to_have_count(1)
    case_services.start_work_item(at_paint, user=operator)
    groups.flush()
    expect(cards).to_have_count(2)
    away = page.locator(f'.card[data-item="{at_paint.pk}"]')
    expect(away).to_have_attribute("data-state", "running")
    expect(away.locator(".away")).to_have_text("At the paint cell: go there to do it.")
    expect(page.locator(f'.card[data-item="{at_weld.pk}"] .away')).to_have_count(0)
    expect(page.locator(".elsewhere")).to_have_text("1 more task waits for you at the paint cell.")

    page.goto(f"{server.url}/tablet/")  # the whole floor: every task, nothing elsewhere
    expect(page.locator(".cards.mine .card")).to_have_count(3)
    expect(page.locator(".elsewhere")).to_have_count(0)


def test_an_operator_claims_a_team_task_gives_it_back_and_claims_it_again(
    server: LiveServer,
    browser: Browser,
    tablet: BrowserContext,
    organisation: Organisation,
    choice_version: PatternVersion,
    operator: User,
    screenshot: Screenshot,
) -> None:
    team = organisation_services.create_team(organisation, name="Shift A")
    colleague = factories.make_member(organisation, Role.OPERATOR, "carl-colleague")
    organisation_services.set_team_members(
        team, Membership.objects.filter(organisation=organisation, user__in=[operator, colleague])
    )
    case = case_services.start_case(
        choice_version, started_by=None, actor_mapping={"o": {"team": "Shift A"}}
    )
    item = WorkItem.objects.get(case=case, task="count")
    page = tablet.new_page()
    _sign_in(page, server.url, operator)
    page.goto(f"{server.url}/tablet/")
    other = browser.new_context(viewport=SMALL, has_touch=True)
    theirs = other.new_page()
    _sign_in(theirs, server.url, colleague)
    theirs.goto(f"{server.url}/tablet/")
    offered = f'.cards.team .card[data-item="{item.pk}"]'
    expect(theirs.locator(offered)).to_be_visible()

    page.locator(offered).get_by_role("button", name="Claim").click()
    mine = page.locator(f'.cards.mine .card[data-item="{item.pk}"]')
    expect(mine).to_have_attribute("data-state", "claimed")
    expect(theirs.locator(offered)).to_have_count(0)  # live: the colleague's tablet drops it
    screenshot(page, "tablet-claimed-give-back")
    assert_fits(page)

    mine.get_by_role("button", name="Give back").click()
    expect(mine).to_have_count(0)
    expect(page.locator(offered)).to_be_visible()
    expect(theirs.locator(offered)).to_be_visible()  # offered to the team again, everywhere
    item.refresh_from_db()
    assert (item.state, item.claimed_by) == ("offered", None)
    given_back = case.events.filter(type=EventType.TASK_UNCLAIMED).get()
    assert given_back.user == operator

    page.locator(offered).get_by_role("button", name="Claim").click()
    expect(mine).to_have_attribute("data-state", "claimed")
    mine.get_by_role("button", name="Start").click()
    expect(mine).to_have_attribute("data-state", "running")
    expect(mine.get_by_role("button", name="Give back")).to_have_count(0)  # started: it stays
    other.close()


def test_an_unknown_cells_tablet_says_so_and_links_the_cells_there_are(
    server: LiveServer, tablet: BrowserContext, organisation: Organisation, operator: User,
    screenshot: Screenshot,
) -> None:  # fmt: skip
    organisation_services.ensure_cell(organisation, "weld")
    organisation_services.ensure_cell(organisation, "paint")
    page = tablet.new_page()
    _sign_in(page, server.url, operator)
    response = page.goto(f"{server.url}/tablet/cell1/")
    assert response is not None
    assert response.status == 404
    expect(page.get_by_role("heading", level=1)).to_have_text(
        f"There is no cell 'cell1' in {organisation.name}"
    )
    expect(page.get_by_role("button", name=re.compile("STOP"))).to_have_count(0)
    screenshot(page, "tablet-unknown-cell")
    assert_fits(page)
    page.set_viewport_size(SMALL)
    screenshot(page, "tablet-unknown-cell-1024x768")
    assert_fits(page)
    page.locator(".cell-links").get_by_role("link", name="weld").click()
    page.wait_for_url(f"{server.url}/tablet/weld/")
    expect(page.locator(".connection")).to_have_text("Live")
