"""`make demo` itself, from a newcomer's start: an operator completes a started use case.

No fixture prepares anything: the demo powers its simulated cobots on as a
person at the pendant would and starts its use cases through its own
server; the worker loads each step's program. Operator1 signs in with the
printed password, opens /tablet/, and does every operator task of the
fixture case (claim, start, choose the mounting position in the form,
complete) while cobot2 picks and holds each part, until the case completes.
Then Ctrl-C (SIGINT to make's process group, as at a terminal) or SIGTERM
ends every process. On the embedded defaults (no DATABASE_URL, no
REDIS_URL) and on a scratch PostgreSQL database with a private Redis.
Screenshots: var/screenshots/demo-plant-*.png.
"""

from __future__ import annotations

import os
import signal
import subprocess
import time
from collections.abc import Callable, Iterator
from contextlib import ExitStack
from pathlib import Path
from typing import Any

import pytest
from playwright.sync_api import Browser, Page, expect

from hrc.demo.plant import STARTED_CASES
from tests.browser.conftest import TABLET
from tests.demo.rig import DemoRun, alive, scratch_postgres
from tests.support.paths import ROOT
from tests.support.polling import until
from tests.support.workers import RedisProcess

Screenshot = Callable[[Page, str], Path]
FIXTURE = STARTED_CASES[1][0]
# The fixture's six mounting positions, as its form lists them.
POSITIONS = ("top left", "top middle", "top right", "bottom left", "bottom middle", "bottom right")
LIVE_MS = 60_000


@pytest.fixture(params=["embedded", "postgresql-redis"])
def demo(request: pytest.FixtureRequest, tmp_path: Path) -> Iterator[DemoRun]:
    # `make demo` installs first: on a checkout whose install is not up to date the test
    # would time out inside pip and npm instead of saying so.
    installed = subprocess.run(["make", "-q", "install"], cwd=ROOT, check=False)
    assert installed.returncode == 0, "Run `make install` first: the install is not up to date."
    with ExitStack() as stack:
        database_url = redis_url = None
        if request.param == "postgresql-redis":
            database_url = stack.enter_context(scratch_postgres(f"hrc_plant_{os.getpid()}"))
            redis = RedisProcess(tmp_path).start()
            stack.callback(redis.stop)
            redis_url = redis.url
        run = DemoRun(tmp_path, database_url=database_url, redis_url=redis_url, make=True)
        stack.callback(run.stop)
        yield run.start()


def test_an_operator_completes_a_started_use_case_on_make_demo_and_ctrl_c_ends_everything(
    demo: DemoRun, browser: Browser, screenshot: Screenshot, request: pytest.FixtureRequest
) -> None:
    began = time.monotonic()
    name = request.node.callspec.id
    output = demo.output()
    assert "cobot1, cobot2: powered on and brakes released" in output
    if "postgresql" in name:
        assert "PostgreSQL hrc_plant_" in output
        assert "a Celery worker with beat" in output
    else:
        assert f"SQLite {demo.workdir / 'var' / 'hrc.sqlite3'}" in output
        assert "embedded mode" in output
    cases = demo.started_cases()
    assert set(cases) == {pattern for pattern, _ in STARTED_CASES}
    fixture = cases[FIXTURE]

    context = browser.new_context(viewport=TABLET, has_touch=True)
    page = context.new_page()
    errors: list[str] = []
    page.on("pageerror", lambda error: errors.append(f"script error: {error}"))
    page.goto(f"{demo.url}/accounts/login/")
    page.get_by_label("User name").fill("operator1")
    page.get_by_label("Password").fill(demo.passwords()["operator1"])
    page.get_by_role("button", name="Sign in").click()
    page.wait_for_url(f"{demo.url}/tablet/")  # an operator lands at the tablet
    expect(page.locator(".connection")).to_have_text("Live")
    cobot2 = page.locator(".cobots .cobot", has_text="cobot2")
    expect(cobot2.locator("dd.mode")).to_have_text("Running", timeout=LIVE_MS)

    for number, position in enumerate(POSITIONS, start=1):
        # The cobot has picked the part: the operator chooses where it goes.
        _do(page, fixture, "choose the mounting position", {"Mounting position *": position})
        if number == 1:
            screenshot(page, f"demo-plant-{name}-form")
        # The cobot holds the part there (func) until the operator has mounted it.
        card = _claim_and_start(page, fixture, "mount the part")
        expect(card.locator(".with-cobots")).to_contain_text("cobot2")
        expect(cobot2.locator(".doing")).to_contain_text(
            f"hold the part at the mounting position (step 3), case {fixture}"
        )
        if number == 1:
            screenshot(page, f"demo-plant-{name}-cobot-holds")
        _complete(page, card, {})

    engineer = demo.token("engineer")
    case = until(
        lambda: _ended(demo.get(engineer, f"/api/cases/{fixture}/")),
        timeout=60,
        interval=0.5,
        message=f"case {fixture} still runs after 60 s",
    )
    assert case["status"] == "completed", case
    assert case["data"]["mounted"] == list(POSITIONS)
    events = demo.get(engineer, f"/api/cases/{fixture}/events/?limit=1000")["results"]
    completed = [
        (e["actor"], e["task"], e["user"]) for e in events if e["type"] == "task-completed"
    ]
    # cobot2 picked and held each part, then went home; operator1 did the rest.
    cobot_steps = [task for actor, task, _ in completed if actor == "c"]
    assert cobot_steps == ["tc_pick", "tc_hold"] * 6 + ["tc_home"], completed
    assert {user for actor, _, user in completed if actor == "o"} == {"operator1"}
    assert not [e for e in events if e["type"] in ("incident-opened", "step-retry")]

    supervisor = context.new_page()  # the engineer sees the same on the case's page
    supervisor.context.clear_cookies()
    supervisor.goto(f"{demo.url}/accounts/login/")
    supervisor.get_by_label("User name").fill("engineer")
    supervisor.get_by_label("Password").fill(demo.passwords()["engineer"])
    supervisor.get_by_role("button", name="Sign in").click()
    supervisor.wait_for_url(f"{demo.url}/")
    supervisor.goto(f"{demo.url}/cases/{fixture}/")
    expect(supervisor.get_by_text("completed").first).to_be_visible()
    screenshot(supervisor, f"demo-plant-{name}-case-completed")
    context.close()
    assert not errors, errors
    operated = time.monotonic() - began

    children = demo.descendants()
    signum = signal.SIGINT if name == "embedded" else signal.SIGTERM
    stopping = time.monotonic()
    assert demo.signal(signum) in (0, -signum)  # make dies of the signal once its child ended
    assert "Stopped; every process the demo started has ended." in demo.output()
    until(
        lambda: not any(alive(pid) for pid in children),
        timeout=30,
        interval=0.2,
        message=lambda: f"still running: {[c for p, c in children.items() if alive(p)]}",
    )
    assert not {pid: command for pid, command in children.items() if alive(pid)}
    print(
        f"\n{name}: demo served in {demo.started_in:.1f} s; the operator's case took "
        f"{operated:.1f} s; stopping took {time.monotonic() - stopping:.1f} s"
    )


def _do(page: Page, case: int, label: str, form: dict[str, str]) -> None:
    _complete(page, _claim_and_start(page, case, label), form)


def _claim_and_start(page: Page, case: int, label: str) -> Any:
    """Claims the team's task `label` of `case` and starts it; returns its card."""
    offered = page.locator(".cards.team .card", has_text=label).filter(has_text=f"case {case} ")
    expect(offered).to_have_count(1, timeout=LIVE_MS)
    item = offered.get_attribute("data-item")
    offered.get_by_role("button", name="Claim").click()
    card = page.locator(f'.cards.mine .card[data-item="{item}"]')
    # Each press is a write to the demo's database, which its workers share: on the embedded
    # SQLite under a loaded machine a write may queue behind theirs for seconds.
    expect(card).to_have_attribute("data-state", "claimed", timeout=LIVE_MS)
    card.get_by_role("button", name="Start").click()
    expect(card).to_have_attribute("data-state", "running", timeout=LIVE_MS)
    return card


def _complete(page: Page, card: Any, form: dict[str, str]) -> None:
    card.get_by_role("button", name="Complete…").click()
    dialog = page.locator(".form-dialog")
    for field, value in form.items():
        dialog.get_by_label(field).select_option(label=value)
    dialog.get_by_role("button", name="Complete").click()
    expect(card).to_have_count(0, timeout=LIVE_MS)


def _ended(case: dict[str, Any]) -> dict[str, Any] | None:
    return case if case["status"] != "running" else None
