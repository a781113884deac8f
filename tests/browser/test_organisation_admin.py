"""An organisation's admin, who is no superuser, sets up the floor in a real browser:
adds an operator (who then signs in with the one-time password), a team with the
operator, a cell and a cobot in that cell. Each page is shot at 1280×800 and
checked for sideways scrolling and cut-off text."""

import re
from collections.abc import Callable
from pathlib import Path

import pytest
from django.contrib.auth.models import User
from playwright.sync_api import Browser, Page, expect

from hrc.cobots.models import Cobot
from hrc.organisations.models import Membership, Organisation, Team
from tests import factories
from tests.browser.conftest import assert_fits

pytestmark = pytest.mark.django_db(transaction=True)

SignIn = Callable[[Page, User], None]
Screenshot = Callable[[Page, str], Path]


def _shot(page: Page, screenshot: Screenshot, name: str) -> None:
    assert_fits(page)
    screenshot(page, name)


def test_an_admin_adds_an_operator_a_team_a_cell_and_a_cobot(
    page: Page,
    browser: Browser,
    live_url: str,
    sign_in: SignIn,
    screenshot: Screenshot,
    admin: User,
    organisation: Organisation,
) -> None:
    assert not admin.is_staff
    assert not admin.is_superuser
    page.set_viewport_size({"width": 1280, "height": 800})
    sign_in(page, admin)

    page.goto(f"{live_url}/organisation/people/")
    form = page.locator("#add-person")
    form.get_by_label("Username", exact=True).fill("otto")
    form.get_by_label("Name", exact=True).fill("Otto Operator")
    form.get_by_label("Role").select_option("operator")
    form.get_by_role("button", name="Add the person").click()
    secret = page.locator("#one-time-password code")
    expect(secret).to_be_visible()
    password = secret.inner_text().strip()
    _shot(page, screenshot, "organisation-people")

    operator_page = browser.new_context(viewport={"width": 1280, "height": 800}).new_page()
    operator_page.goto(f"{live_url}/accounts/login/")
    operator_page.get_by_label("User name").fill("otto")
    operator_page.get_by_label("Password").fill(password)
    operator_page.get_by_role("button", name="Sign in").click()
    operator_page.wait_for_url(f"{live_url}/tablet/")  # an operator lands on the tablet
    operator_page.context.close()

    page.goto(f"{live_url}/organisation/teams/")
    form = page.locator("#add-team")
    form.get_by_label("Name", exact=True).fill("Morning shift")
    form.get_by_label("otto").check()
    form.get_by_role("button", name="Create the team").click()
    expect(page.locator("table.teams")).to_contain_text("otto")
    _shot(page, screenshot, "organisation-teams")

    page.goto(f"{live_url}/organisation/cells/")
    form = page.locator("#add-cell")
    form.get_by_label("Name", exact=True).fill("cell 1")
    form.get_by_role("button", name="Create the cell").click()
    expect(page.locator("#id_name-errors")).to_contain_text("not a cell name")
    page.locator("#add-cell").get_by_label("Name", exact=True).fill("cell1")
    page.locator("#add-cell").get_by_label("Description").fill("Assembly, by the north door")
    page.locator("#add-cell").get_by_role("button", name="Create the cell").click()
    expect(page.get_by_role("link", name="/tablet/cell1/")).to_be_visible()
    _shot(page, screenshot, "organisation-cells")

    page.goto(f"{live_url}/cobots/")
    page.get_by_role("link", name="Register a cobot").click()
    form = page.locator("#cobot-form")
    form.get_by_label("Name", exact=True).fill("cobot7")
    form.get_by_label("Endpoint").fill("opc.tcp://127.0.0.1:4899")
    form.get_by_label("Cell").select_option("cell1")
    _shot(page, screenshot, "cobot-new")
    form.get_by_role("button", name="Register the cobot").click()
    expect(page.get_by_role("heading", name="cobot7")).to_be_visible()
    page.get_by_role("link", name="Edit").click()
    expect(page.locator("#cobot-form")).to_be_visible()
    _shot(page, screenshot, "cobot-edit")

    membership = Membership.objects.get(user__username="otto", organisation=organisation)
    assert membership.role == "operator"
    assert list(Team.objects.get(name="Morning shift").members.all()) == [membership]
    assert Cobot.objects.get(name="cobot7").cell == "cell1"
    assert re.fullmatch(r"[A-Za-z0-9_-]{16}", password)


def test_the_detail_pages_and_the_invitation_fit_the_window(
    page: Page,
    browser: Browser,
    live_url: str,
    sign_in: SignIn,
    screenshot: Screenshot,
    admin: User,
    operator: User,
    organisation: Organisation,
) -> None:
    membership = Membership.objects.get(user=operator)
    team = Team.objects.create(organisation=organisation, name="Night shift")
    team.members.add(membership)
    factories.make_cobot(organisation, name="welder", cell="weld")
    page.set_viewport_size({"width": 1280, "height": 800})
    sign_in(page, admin)

    page.goto(f"{live_url}/organisation/people/")
    page.get_by_role("link", name=operator.username).click()
    page.get_by_role("button", name="Reset the password").click()
    expect(page.locator("#one-time-password code")).to_be_visible()
    _shot(page, screenshot, "organisation-person")

    page.goto(f"{live_url}/organisation/teams/")
    page.get_by_role("link", name="Night shift").click()
    expect(page.get_by_label(operator.username)).to_be_checked()
    _shot(page, screenshot, "organisation-team")

    page.goto(f"{live_url}/organisation/cells/")
    page.get_by_role("link", name="weld", exact=True).click()
    page.once("dialog", lambda dialog: dialog.accept())
    page.get_by_role("button", name="Delete the cell").click()
    expect(page.get_by_role("alert")).to_contain_text("welder")
    _shot(page, screenshot, "organisation-cell")

    page.goto(f"{live_url}/organisation/people/")
    form = page.locator("#add-person")
    form.get_by_label("Username", exact=True).fill("ivy")
    form.get_by_label("Invitation link").check()
    form.get_by_role("button", name="Add the person").click()
    link = page.locator("#invitation").inner_text().strip()

    invited = browser.new_context(viewport={"width": 1280, "height": 800}).new_page()
    invited.goto(link)
    expect(invited.get_by_role("heading", name="Welcome, ivy")).to_be_visible()
    _shot(invited, screenshot, "organisation-join")
    invited.get_by_label("New password", exact=True).fill("a-long-chosen-password-42")
    invited.get_by_label("New password confirmation").fill("a-long-chosen-password-42")
    invited.get_by_role("button", name="Set my password").click()
    invited.wait_for_url(re.compile(r".*/accounts/login/.*"))
    invited.get_by_label("User name").fill("ivy")
    invited.get_by_label("Password").fill("a-long-chosen-password-42")
    invited.get_by_role("button", name="Sign in").click()
    expect(invited).not_to_have_url(re.compile(r"/accounts/login/"))  # signed in, sent on
    invited.context.close()
