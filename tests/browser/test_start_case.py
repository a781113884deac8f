"""Running a version in the browser: its page, the start form, a case steered from its page,
and an operator's cycle started at a cell's tablet. Each page fits its screen
(var/screenshots/start-*.png)."""

from collections.abc import Callable
from pathlib import Path

import pytest
from django.contrib.auth.models import User
from playwright.sync_api import Page, ViewportSize, expect

from hrc.cases.choices import CaseStatus
from hrc.cases.models import Case
from hrc.cobots.models import Cobot
from hrc.organisations.models import Organisation
from hrc.organisations.services import ensure_cell
from hrc.patterns.models import PatternVersion
from tests import factories
from tests.browser.conftest import assert_fits

pytestmark = pytest.mark.django_db(transaction=True)

SignIn = Callable[[Page, User], None]
Screenshot = Callable[[Page, str], Path]
DESK = ViewportSize(width=1280, height=800)
SMALL_TABLET = ViewportSize(width=1024, height=768)


@pytest.fixture
def version(organisation: Organisation, engineer: User) -> PatternVersion:
    document = factories.valid_document()
    document["data"] = {"batch": 1, "urgent": False, "spots": [[0.1, 0.2, 0.05, 0, 0, 0]]}
    return factories.make_version(organisation, published_by=engineer, draft=document)


def test_an_engineer_maps_the_version_starts_two_cases_and_steers_one(
    page: Page,
    live_url: str,
    engineer: User,
    operator: User,
    cobot: Cobot,
    organisation: Organisation,
    version: PatternVersion,
    sign_in: SignIn,
    screenshot: Screenshot,
) -> None:
    ensure_cell(organisation, "cell-a")
    page.set_viewport_size(DESK)
    sign_in(page, engineer)
    page.goto(f"{live_url}/patterns/")
    page.get_by_role("link", name="v1").click()
    expect(page.get_by_role("heading", name="Default mapping")).to_be_visible()
    page.get_by_label("o (operator)").select_option(label=operator.username)
    page.get_by_label("c (cobot)").select_option(label=f"{cobot.name}")
    page.get_by_role("button", name="Save the mapping").click()
    expect(page.get_by_role("status")).to_have_text("The default mapping is saved.")
    assert_fits(page)
    screenshot(page, "start-version-page")

    page.get_by_role("link", name="Start a case").first.click()
    # Wrong input is shown at its field, and nothing starts.
    page.get_by_label("c (cobot)").select_option("")
    page.get_by_label("spots *").fill("[1, 2")
    page.get_by_role("button", name="Start", exact=True).click()
    expect(page.locator(".field.invalid")).to_have_count(2)
    expect(page.get_by_text("This is not JSON")).to_be_visible()
    assert not Case.objects.exists()
    assert_fits(page)
    screenshot(page, "start-form-refused")

    page.get_by_label("c (cobot)").select_option(label=cobot.name)
    page.get_by_label("batch *").fill("3")
    page.get_by_label("spots *").fill("[[0.1, 0.2, 0.05, 0, 0, 0]]")
    page.get_by_label("urgent *").select_option("yes")
    page.get_by_label("Reference").fill("ORDER-42")
    page.get_by_label("Count *").fill("2")
    page.get_by_role("button", name="Start", exact=True).click()
    rows = page.locator("table.cases tbody tr")
    expect(rows).to_have_count(2)
    expect(rows.first).to_contain_text("ORDER-42")
    assert_fits(page)
    screenshot(page, "start-cases-started")
    cases = list(Case.objects.order_by("pk"))
    assert [(c.data["batch"], c.data["urgent"], c.reference) for c in cases] == [
        (3, True, "ORDER-42")
    ] * 2

    page.goto(f"{live_url}/cases/{cases[0].pk}/")
    page.get_by_role("button", name="Suspend").click()
    expect(page.locator("#case-status")).to_have_text("Suspended")
    page.get_by_role("button", name="Resume").click()
    expect(page.locator("#case-status")).to_have_text("Running")
    page.get_by_text("Cancel the case…").click()
    page.get_by_label("Yes, cancel this case").check()
    assert_fits(page)
    screenshot(page, "start-case-cancel")
    page.get_by_role("button", name="Cancel the case").click()
    expect(page.locator("#case-status")).to_have_text("Cancelled")
    cases[0].refresh_from_db()
    assert cases[0].status == CaseStatus.CANCELLED


def test_an_operator_starts_a_cycle_at_the_cell_and_a_mistyped_cell_says_so(
    page: Page,
    live_url: str,
    engineer: User,
    operator: User,
    cobot: Cobot,
    organisation: Organisation,
    version: PatternVersion,
    sign_in: SignIn,
    screenshot: Screenshot,
) -> None:
    ensure_cell(organisation, "cell-a")
    sign_in(page, engineer)
    page.goto(f"{live_url}/patterns/versions/{version.pk}/")
    page.get_by_label("o (operator)").select_option(label=operator.username)
    page.get_by_label("c (cobot)").select_option(label=cobot.name)
    page.get_by_role("button", name="Save the mapping").click()
    page.get_by_role("group", name="Roles that may start it").get_by_label("Operator").check()
    page.get_by_role("group", name="Cells whose tablets offer it to operators").get_by_label(
        "cell-a"
    ).check()
    page.get_by_role("button", name="Save who may start it").click()
    expect(page.get_by_role("status")).to_have_text("Who may start it is saved.")
    page.context.clear_cookies()

    page.set_viewport_size(SMALL_TABLET)
    sign_in(page, operator)
    page.goto(f"{live_url}/tablet/cell-a/")
    cycle = page.locator("details.cycle")
    cycle.locator("summary").click()
    cycle.get_by_label("Reference").fill("W-7")
    cycle.get_by_label("batch *").fill("2")
    assert_fits(page)
    screenshot(page, "start-cycle-at-the-cell")
    cycle.get_by_role("button", name="Start").click()
    expect(page.get_by_role("status").filter(has_text="started")).to_be_visible()
    case = Case.objects.get()
    assert (case.reference, case.data["batch"], case.started_by) == ("W-7", 2, operator)

    page.goto(f"{live_url}/tablet/cell1/")
    expect(page.get_by_role("heading", name="There is no cell 'cell1'")).to_be_visible()
    expect(page.get_by_role("link", name="cell-a")).to_be_visible()
    expect(page.get_by_role("button", name="STOP every cobot of the cell")).to_have_count(0)
    assert_fits(page)
    screenshot(page, "start-unknown-cell")
