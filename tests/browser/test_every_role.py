"""Every role at home in the browser, from `manage.py demo` as a newcomer meets it.

On the embedded defaults and on PostgreSQL with Redis (a Celery worker),
with a third simulated cobot that boots as a real one does (powered off,
no program):

1. the demo's admin, who is no superuser, adds an operator (with a one-time
   password), a team with them, a cell and the cobot in that cell;
2. the engineer powers the cobot on at its page, draws and publishes a
   pattern, sets its mapping and start rights on the version's page and
   starts two cases from the start form;
3. the new operator signs in with the one-time password, lands on the
   tablet, goes to the cell's tablet, claims a task, gives it back, claims it
   again and does every task while the cobot runs its steps;
4. both cases complete and show in analytics;
5. the operator starts a cycle from the cell's tablet.

Screenshots: var/screenshots/every-role-*.png, each page checked to fit.
"""

from __future__ import annotations

import os
import re
from collections.abc import Callable, Iterator
from contextlib import ExitStack
from functools import partial
from pathlib import Path
from typing import Any

import pytest
from playwright.sync_api import Browser, Page, ViewportSize, expect

from hrc.cobots.simulated import GatewayProcess
from tests.browser.conftest import TABLET, assert_fits
from tests.browser.drawing import (
    CHECKED,
    append_node,
    centre_of,
    connect,
    drop_tool,
    element_box,
    open_editor,
    pad_action,
    pattern_badge,
    select_element,
)
from tests.demo.rig import DemoRun, scratch_postgres
from tests.support.polling import until
from tests.support.workers import RedisProcess

Screenshot = Callable[[Page, str], Path]
LIVE_MS = 60_000
PATTERN = "Press loading"
CELL = "press"
COBOT = "press-arm"
TEAM = "Press crew"
OPERATOR = "olga"
# An engineer's or admin's screen.
DESK = ViewportSize(width=1280, height=800)


@pytest.fixture(params=["embedded", "postgresql-redis"])
def plant(request: pytest.FixtureRequest, tmp_path: Path) -> Iterator[tuple[DemoRun, str]]:
    """The demo with no case started, and a cobot of the plant's own that nobody has prepared."""
    with ExitStack() as stack:
        database_url = redis_url = None
        if request.param == "postgresql-redis":
            database_url = stack.enter_context(scratch_postgres(f"hrc_roles_{os.getpid()}"))
            redis = RedisProcess(tmp_path).start()
            stack.callback(redis.stop)
            redis_url = redis.url
        arm = GatewayProcess(COBOT, tmp_path / "press-arm.json", time_scale=0.05).start()
        stack.callback(arm.stop)
        run = DemoRun(
            tmp_path, database_url=database_url, redis_url=redis_url, arguments=["--no-cases"]
        )
        stack.callback(run.stop)
        yield run.start(), arm.endpoint


def test_each_role_does_its_part_from_a_fresh_demo(
    plant: tuple[DemoRun, str],
    browser: Browser,
    screenshot: Screenshot,
    request: pytest.FixtureRequest,
) -> None:
    demo, endpoint = plant
    name = request.node.callspec.id
    errors: list[str] = []

    def person(username: str, password: str, viewport: ViewportSize = DESK) -> Page:
        context = browser.new_context(viewport=viewport)
        page = context.new_page()
        page.on("pageerror", lambda error: errors.append(f"{username}: {error}"))
        page.goto(f"{demo.url}/accounts/login/")
        page.get_by_label("User name").fill(username)
        page.get_by_label("Password").fill(password)
        page.get_by_role("button", name="Sign in").click()
        expect(page).not_to_have_url(re.compile(r"/accounts/login/"))
        return page

    def shot(page: Page, what: str) -> None:
        assert_fits(page)
        screenshot(page, f"every-role-{name}-{what}")

    passwords = demo.passwords()

    # 1. The admin sets up the cell. -------------------------------------------------------
    admin = person("admin", passwords["admin"])
    one_time_password = _admin_sets_up_the_cell(admin, endpoint, shot)
    admin.context.close()

    # 2. The engineer prepares the cobot, draws, publishes, maps and starts two cases. ----
    engineer = person("engineer", passwords["engineer"])
    engineer.goto(f"{demo.url}/cobots/")
    engineer.get_by_role("link", name=COBOT).click()
    # The cobot booted powered off, as a real one does: a person powers it on (and, as
    # URUA's PowerOn did, releases its brakes); hrc's worker loads the programs itself.
    engineer.get_by_role("button", name="Power on").click()
    engineer.get_by_role("dialog").get_by_role("button", name="Confirm").click()
    expect(engineer.locator("#outcome")).to_have_text(f"Power on: {COBOT} done.", timeout=LIVE_MS)
    expect(engineer.locator('[data-state="RobotMode"]')).to_have_text("Running", timeout=LIVE_MS)
    shot(engineer, "cobot-powered-on")

    version_url = _engineer_draws_and_publishes(engineer, demo.url, shot)
    engineer.get_by_label(re.compile(r"\(operator\)")).select_option(label=f"Team {TEAM}")
    engineer.get_by_label(re.compile(r"\(cobot\)")).select_option(label=f"{COBOT} (cell {CELL})")
    engineer.get_by_role("button", name="Save the mapping").click()
    expect(engineer.get_by_role("status")).to_have_text("The default mapping is saved.")
    rights = engineer.get_by_role("group", name="Roles that may start it")
    rights.get_by_label("Operator").check()
    engineer.get_by_role("group", name="Cells whose tablets offer it to operators").get_by_label(
        CELL
    ).check()
    engineer.get_by_role("button", name="Save who may start it").click()
    expect(engineer.get_by_role("status")).to_have_text("Who may start it is saved.")
    shot(engineer, "version-page")
    engineer.get_by_role("link", name="Start a case").first.click()
    engineer.get_by_label("Reference").fill("ORDER-1")
    engineer.get_by_label("Count *").fill("2")
    shot(engineer, "start-form")
    engineer.get_by_role("button", name="Start", exact=True).click()
    expect(engineer.locator("table.cases tbody tr")).to_have_count(2)
    shot(engineer, "cases-started")
    token = demo.token("engineer")
    version = int(version_url.rstrip("/").rsplit("/", 1)[1])
    cases = [c["id"] for c in demo.get(token, f"/api/cases/?version={version}")["results"]]
    assert len(cases) == 2

    # 3. The operator does the work at the cell's tablet. ----------------------------------
    tablet = person(OPERATOR, one_time_password, TABLET)
    expect(tablet).to_have_url(f"{demo.url}/tablet/")
    tablet.goto(f"{demo.url}/tablet/{CELL}/")
    expect(tablet.locator(".connection")).to_have_text("Live")
    first = True
    for case in sorted(cases):
        card = _claim(tablet, case, "load the press")
        if first:
            # Given back, it is the team's again; claimed again, it is the operator's.
            card.get_by_role("button", name="Give back").click()
            card = _claim(tablet, case, "load the press")
            shot(tablet, "claimed-again")
            first = False
        card.get_by_role("button", name="Start").click()
        expect(card).to_have_attribute("data-state", "running")
        card.get_by_role("button", name="Complete…").click()
        tablet.locator(".form-dialog").get_by_role("button", name="Complete").click()
        expect(card).to_have_count(0, timeout=LIVE_MS)

    # 4. Both complete, and show in analytics. ---------------------------------------------
    for case in cases:
        done = until(partial(_ended, demo, token, case), timeout=90)
        assert done["status"] == "completed", done
    engineer.goto(f"{demo.url}/analytics/")
    engineer.get_by_role("link", name=re.compile(PATTERN)).first.click()
    expect(engineer.locator('#case-counts [data-status="completed"]')).to_have_text("2 completed")
    shot(engineer, "analytics")

    # 5. The operator starts a cycle at the cell's tablet. ----------------------------------
    tablet.goto(f"{demo.url}/tablet/{CELL}/")
    cycle = tablet.locator("details.cycle", has_text=PATTERN)
    cycle.locator("summary").click()
    cycle.get_by_label("Reference").fill("ORDER-2")
    shot(tablet, "start-a-cycle")
    cycle.get_by_role("button", name="Start").click()
    expect(tablet.get_by_role("status").filter(has_text="started")).to_be_visible()
    started = demo.get(token, f"/api/cases/?version={version}")["results"]
    assert len(started) == 3
    assert {c["reference"] for c in started} == {"ORDER-1", "ORDER-2"}
    tablet.set_viewport_size({"width": 1024, "height": 768})
    shot(tablet, "tablet-1024")
    assert not errors, errors


def _admin_sets_up_the_cell(page: Page, endpoint: str, shot: Callable[[Page, str], None]) -> str:
    """Adds the operator, the team, the cell and the cobot; returns the one-time password."""
    expect(page.get_by_role("link", name="Site admin")).to_have_count(0)  # no superuser
    page.get_by_role("link", name="Administration").click()
    form = page.locator("#add-person")
    form.get_by_label("Username", exact=True).fill(OPERATOR)
    form.get_by_label("Name", exact=True).fill("Olga Operator")
    form.get_by_label("Role").select_option("operator")
    form.get_by_role("button", name="Add the person").click()
    secret = page.locator("#one-time-password code")
    expect(secret).to_be_visible()
    password = secret.inner_text().strip()
    shot(page, "people")

    page.goto(page.url.replace("/people/", "/teams/"))
    form = page.locator("#add-team")
    form.get_by_label("Name", exact=True).fill(TEAM)
    form.get_by_label(OPERATOR).check()
    form.get_by_role("button", name="Create the team").click()
    expect(page.locator("table.teams")).to_contain_text(OPERATOR)
    shot(page, "teams")

    page.goto(page.url.replace("/teams/", "/cells/"))
    form = page.locator("#add-cell")
    form.get_by_label("Name", exact=True).fill(CELL)
    form.get_by_label("Description").fill("The press, by the loading bay")
    form.get_by_role("button", name="Create the cell").click()
    expect(page.get_by_role("link", name=f"/tablet/{CELL}/")).to_be_visible()
    shot(page, "cells")

    page.locator("header.site").get_by_role("link", name="Cobots", exact=True).click()
    page.get_by_role("link", name="Register a cobot").click()
    form = page.locator("#cobot-form")
    form.get_by_label("Name", exact=True).fill(COBOT)
    form.get_by_label("Endpoint").fill(endpoint)
    form.get_by_label("Cell").select_option(CELL)
    shot(page, "cobot-new")
    form.get_by_role("button", name="Register the cobot").click()
    expect(page.get_by_role("heading", name=COBOT)).to_be_visible()
    return password


def _engineer_draws_and_publishes(page: Page, url: str, shot: Callable[[Page, str], None]) -> str:
    """Draws the operator loading the press, then the cobot pressing (a time constraint between
    them), publishes, and follows the link to the version's page; returns its address."""
    open_editor(page, f"{url}/patterns/new/")
    name = page.get_by_label("Pattern name")
    name.fill(PATTERN)
    name.press("Enter")
    page.get_by_role("button", name="Cobot lane").click()
    page.get_by_role("button", name="Operator lane").click()
    cobot, operator = element_box(page, "c"), element_box(page, "o")
    page.mouse.click(cobot["x"] + 10, cobot["y"] + cobot["height"] / 2)
    program = page.get_by_role("region", name="Properties").get_by_label("Default program")
    program.fill("Synchronized_SpotTaping")
    program.press("Tab")
    # The cobot's line: p1 (the case's token), a split t1, then pressing; the operator's line
    # from the split, loading; both join in t2. The cobot presses only a loaded press.
    drop_tool(page, "Place", cobot["x"] + 100, cobot["y"] + cobot["height"] / 2)
    pad_action(page, "token.add")
    pad_action(page, "append.silent")
    append_node(page)  # p2
    append_node(page, "press the part")  # tc1
    append_node(page)  # p3
    x, _ = centre_of(page, "p2")
    drop_tool(page, "Place", x, operator["y"] + operator["height"] / 2)  # p4
    append_node(page, "load the press")  # to1
    append_node(page)  # p5
    select_element(page, "p3")
    pad_action(page, "append.silent")  # t2
    append_node(page)  # p6
    connect(page, "t1", "p4")
    connect(page, "p5", "t2")
    connect(page, "to1", "tc1", "constraint.time")
    expect(pattern_badge(page)).to_have_attribute("data-valid", "true", timeout=CHECKED)
    shot(page, "editor-drawn")
    page.get_by_role("button", name="Publish", exact=True).click()
    page.get_by_role("link", name="Published version 1.").click()
    page.wait_for_url(re.compile(r"/patterns/versions/\d+/$"))
    return page.url


def _claim(page: Page, case: int, label: str) -> Any:
    offered = page.locator(".cards.team .card", has_text=label).filter(has_text=f"case {case} ")
    expect(offered).to_have_count(1, timeout=LIVE_MS)
    item = offered.get_attribute("data-item")
    offered.get_by_role("button", name="Claim").click()
    card = page.locator(f'.cards.mine .card[data-item="{item}"]')
    expect(card).to_have_attribute("data-state", "claimed")
    return card


def _ended(demo: DemoRun, token: str, case: int) -> dict[str, Any] | None:
    """The case once it has ended, else None."""
    found = demo.get(token, f"/api/cases/{case}/")
    return found if found["status"] != "running" else None
