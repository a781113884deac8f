"""`make demo` itself, from the state a newcomer starts in, and an operator working a started case.

Nothing prepares the demo: `make demo` runs from the project root with no
DATABASE_URL and no REDIS_URL (the embedded defaults), or on a scratch
PostgreSQL database and a private redis-server, with var/, the simulator's
state and the certificates in a temporary folder. The demo itself powers its
cobots on and starts the use cases; the operator signs in with the printed
password and, on the tablet, claims, starts, fills in and completes every
task of the fixture case while cobot2 picks and holds each part, until the
case completes. Ctrl-C then ends every process. Screenshots:
var/screenshots/make-demo-*.png.
"""

from __future__ import annotations

import os
import re
import signal
import time
from collections.abc import Callable, Iterator
from contextlib import ExitStack
from pathlib import Path

import pytest
from playwright.sync_api import Locator, Page, expect

from hrc.cases.launcher import RedisProcess
from hrc.demo import plant
from tests.demo.rig import DemoRun, alive, scratch_postgres

Screenshot = Callable[[Page, str], Path]
FIXTURE = "Use case 6: fixture (1 operator, 1 cobot)"
# The positions in the order the operator chooses them: every one, none twice.
POSITIONS = ("top left", "bottom right", "top middle", "bottom left", "top right", "bottom middle")
# A change on the tablet within this many milliseconds, with no reload, came over the socket.
LIVE_MS = 60_000
# Records every line the cobot panels show, as they render: a step at --time-scale 0.05 is
# over in well under a second, quicker than a test can look at the page.
WATCH_PANELS = """() => {
  window.panelLines = [];
  const note = () => document.querySelectorAll('.cobots .cobot').forEach((panel) => {
    window.panelLines.push(panel.querySelector('h3').textContent + ': '
      + panel.querySelector('.doing').textContent);
  });
  new MutationObserver(note).observe(document.querySelector('.cobots'),
    {childList: true, subtree: true, characterData: true});
  note();
}"""


@pytest.fixture(params=["embedded", "postgresql-redis"])
def demo(request: pytest.FixtureRequest, tmp_path: Path) -> Iterator[DemoRun]:
    """`make demo` started as a newcomer starts it, on one of the two configurations."""
    with ExitStack() as stack:
        database_url = redis_url = None
        if request.param == "postgresql-redis":
            database_url = stack.enter_context(scratch_postgres(f"hrc_make_demo_{os.getpid()}"))
            redis = RedisProcess(tmp_path).start()
            stack.callback(redis.stop)
            redis_url = redis.url
        run = DemoRun(tmp_path, database_url=database_url, redis_url=redis_url, make=True)
        stack.callback(run.stop)
        yield run.start()


def test_an_operator_completes_a_case_the_demo_started_while_its_cobot_runs_each_step(
    demo: DemoRun, page: Page, screenshot: Screenshot
) -> None:
    began = time.monotonic()
    output = demo.output()
    if _name(demo) == "embedded":  # the newcomer's default: SQLite in var/, jobs on threads
        assert f"SQLite {demo.workdir / 'var' / 'hrc.sqlite3'}" in output
        assert "embedded mode" in output
    else:
        assert "PostgreSQL hrc_make_demo_" in output
        assert "a Celery worker with beat" in output
    assert "cobot1, cobot2: powered on and brakes released" in output
    case = demo.started_cases()[FIXTURE]
    assert set(demo.started_cases()) == {name for name, _ in plant.STARTED_CASES}

    page.goto(f"{demo.url}/accounts/login/")
    page.get_by_label("User name").fill("operator1")
    page.get_by_label("Password").fill(demo.passwords()["operator1"])
    page.get_by_role("button", name="Sign in").click()
    page.wait_for_url(f"{demo.url}/")
    page.goto(f"{demo.url}/tablet/")
    expect(page.locator(".connection")).to_have_text("Live")
    page.evaluate(WATCH_PANELS)
    cobot2 = page.locator(".cobot", has=page.get_by_role("heading", name="cobot2"))
    expect(cobot2.locator("dd.mode")).to_have_text("Running", timeout=LIVE_MS)  # the demo did it

    of_case = re.compile(rf"\bcase {case} ·")
    for number, position in enumerate(POSITIONS, start=1):
        choose = _task(page, "choose the mounting position", of_case)
        _claim_and_start(choose)
        choose.get_by_role("button", name="Complete…").click()
        dialog = page.locator(".form-dialog")
        dialog.get_by_label("Mounting position *").select_option(label=position)
        if number == 1:
            screenshot(page, f"make-demo-{_name(demo)}-form")
        dialog.get_by_role("button", name="Complete").click()
        expect(choose).to_have_count(0, timeout=LIVE_MS)

        mount = _task(page, "mount the part", of_case)
        _claim_and_start(mount)
        # The cobot holds the part where the operator chose until they confirm the mounting.
        expect(mount.locator(".with-cobots")).to_contain_text("cobot2")
        if number == 1:
            screenshot(page, f"make-demo-{_name(demo)}-holding")
        mount.get_by_role("button", name="Complete…").click()
        page.locator(".form-dialog").get_by_role("button", name="Complete").click()
        expect(mount).to_have_count(0, timeout=LIVE_MS)

    status = _until(lambda: demo.api("engineer", f"/api/cases/{case}/")["status"] == "completed")
    assert status
    screenshot(page, f"make-demo-{_name(demo)}-done")
    lines = page.evaluate("window.panelLines")
    # The panel showed cobot2 working this case's steps: picking, holding, going home.
    for label in ("pick a part (step 2)", "hold the part at the mounting position (step 3)",
                  "move home (step 1)"):  # fmt: skip
        assert f"cobot2: {label}, case {case}" in lines, (label, sorted(set(lines)))
    events = demo.api("engineer", f"/api/cases/{case}/events/?limit=1000")["results"]
    completed = [event["task"] for event in events if event["type"] == "task-completed"]
    assert completed.count("tc_pick") == completed.count("tc_hold") == 6
    assert completed.count("to_mount") == 6
    assert "incident-opened" not in {event["type"] for event in events}
    worked = time.monotonic() - began

    children = demo.descendants()
    demo.signal(signal.SIGINT)
    assert "every process the demo started has ended" in demo.output()
    left = {pid: command for pid, command in children.items() if alive(pid)}
    assert not left, left
    print(
        f"\n{_name(demo)}: make demo served in {demo.started_in:.1f} s; case worked in {worked:.1f} s"
    )


def _task(page: Page, label: str, of_case: re.Pattern[str]) -> Locator:
    """The card of the case's open task `label`, once the tablet shows it."""
    card = page.locator(".card", has_text=label).filter(has_text=of_case)
    expect(card).to_have_count(1, timeout=LIVE_MS)
    return card


def _claim_and_start(card: Locator) -> None:
    """Claims the task when it is offered to the team, then starts it: the person's two taps."""
    button = card.locator("button.action")
    expect(button).to_be_visible()
    if button.get_attribute("data-action") == "claim":
        button.click()
        expect(card).to_have_attribute("data-state", "claimed", timeout=LIVE_MS)
    card.get_by_role("button", name="Start").click()
    expect(card).to_have_attribute("data-state", "running", timeout=LIVE_MS)


def _until(condition: Callable[[], object], timeout: float = 60.0) -> object:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        value = condition()
        if value:
            return value
        time.sleep(0.2)
    raise AssertionError("condition not reached in time")


def _name(demo: DemoRun) -> str:
    return "postgresql" if "DATABASE_URL" in demo.environment else "embedded"
