"""A newcomer's first case: `make demo` as the README says, an operator on the tablet, to the end.

Nothing is prepared by a fixture: `make demo` starts its gateways as cobots
boot (powered off, no program), powers them on as the person at the pendant
would, and starts its use-case cases; the operator signs in with the printed
password and does every task of the polishing case on the tablet while the
cobot polishes each line, until the case completes. Once on the embedded
default (no DATABASE_URL, no REDIS_URL), once on PostgreSQL and Redis (a
scratch database and a private redis-server). Screenshots:
var/screenshots/demo-plant-*.png.
"""

from __future__ import annotations

import json
import signal
import time
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest
from playwright.sync_api import Browser, Page, expect

from hrc.cases.launcher import RedisProcess
from tests.demo.rig import Browserless, DemoRun, alive, scratch_postgres

Screenshot = Callable[[Page, str], Path]
POLISHING = "Use case 5: polishing (1 operator, 1 cobot)"
LINES = 6
# A line is polished in a few seconds at --time-scale 0.05; a loaded CI machine is slower.
TASK_MS = 120_000


@pytest.fixture(params=["embedded", "postgres-redis"])
def demo(request: pytest.FixtureRequest, tmp_path: Path) -> Iterator[DemoRun]:
    if request.param == "embedded":
        run = DemoRun(tmp_path, database_url=None, via_make=True)
        yield run.start()
        run.stop()
        return
    with scratch_postgres(f"hrc_demo_plant_{tmp_path.name[-12:]}") as database_url:
        broker = RedisProcess(tmp_path).start()
        run = DemoRun(tmp_path, database_url=database_url, redis_url=broker.url, via_make=True)
        try:
            yield run.start()
        finally:
            run.stop()
            broker.stop()


def _case_status(engineer: Browserless, case: int) -> str:
    status, _, body = engineer.get(f"/api/cases/{case}/")
    assert status == 200, body
    return str(json.loads(body)["status"])


def test_an_operator_completes_a_started_use_case_on_the_tablet_while_its_cobot_works(
    demo: DemoRun, browser: Browser, screenshot: Screenshot
) -> None:
    passwords = demo.passwords()
    case = demo.started_cases()[POLISHING]
    assert "cobot1: powered on and brakes released" in demo.output()
    page = browser.new_context(viewport={"width": 1280, "height": 800}, has_touch=True).new_page()
    page.goto(f"{demo.url}/accounts/login/")
    page.get_by_label("User name").fill("operator1")
    page.get_by_label("Password").fill(passwords["operator1"])
    page.get_by_role("button", name="Sign in").click()
    page.goto(f"{demo.url}/tablet/")
    expect(page.locator(".connection")).to_have_text("Live")

    for line in range(1, LINES + 1):
        label = f"check and fine-polish line {line}"
        offered = page.locator(".cards .card", has_text=label)
        # Offered once the cobot has polished the line (a time constraint): the cobot works first.
        expect(offered).to_be_visible(timeout=TASK_MS)
        if line == 1:
            screenshot(page, "demo-plant-first-task")
        offered.get_by_role("button", name="Claim").click()
        mine = page.locator(".cards.mine .card", has_text=label)
        mine.get_by_role("button", name="Start").click()
        expect(mine).to_have_attribute("data-state", "running")
        mine.get_by_role("button", name="Complete…").click()
        page.locator(".form-dialog").get_by_role("button", name="Complete").click()
        expect(page.locator(".card", has_text=label)).to_have_count(0, timeout=TASK_MS)

    engineer = Browserless(demo.url)
    assert engineer.sign_in("engineer", passwords["engineer"])
    deadline = time.monotonic() + TASK_MS / 1000
    while _case_status(engineer, case) != "completed" and time.monotonic() < deadline:
        time.sleep(0.5)
    assert _case_status(engineer, case) == "completed"
    _, _, page_text = engineer.get(f"/cases/{case}/")
    assert "completed" in page_text.lower()
    screenshot(page, "demo-plant-done")

    # Ctrl-C at the terminal: make and the demo both get it; the demo stops what it started.
    processes = demo.descendants()
    demo.signal(signal.SIGINT)
    deadline = time.monotonic() + 60
    while any(alive(pid) for pid in processes) and time.monotonic() < deadline:
        time.sleep(0.2)
    assert [command for pid, command in processes.items() if alive(pid)] == []
    assert "every process the demo started has ended" in demo.output()
