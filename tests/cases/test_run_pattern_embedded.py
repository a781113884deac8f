"""`manage.py run_pattern --simulate` on the embedded default, as the README runs it after cloning.

Each file of the example library and of the use cases runs in a child process with no
DATABASE_URL and no REDIS_URL (SQLite in WAL mode, jobs on threads of the command), its
files under a scratch HRC_VAR_DIR that does not exist yet: the command creates and
migrates the database itself. Every case must complete, and its trace keep every
constraint (the same checker as the PostgreSQL runs in test_run_pattern.py).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from collections import Counter
from pathlib import Path

import pytest

from hrc.engine.document import read_pattern
from tests.cases import patterns
from tests.cases.test_run_pattern import EVENTS, Event, check_trace

ROOT = Path(__file__).parents[2]
EXAMPLES = ROOT / "hrc" / "patterns" / "examples"
FILES = sorted(EXAMPLES.glob("*.json")) + sorted((EXAMPLES / "use_cases").glob("*.json"))


def embedded_environment(scratch: Path) -> dict[str, str]:
    """The environment of a fresh clone: no PostgreSQL, no Redis, the files under `scratch`."""
    environment = {
        name: value
        for name, value in os.environ.items()
        if name not in {"DATABASE_URL", "REDIS_URL"} and not name.startswith("PYTEST_")
    }
    environment.update(
        DJANGO_SETTINGS_MODULE="hrc.settings.dev",
        HRC_VAR_DIR=str(scratch / "var"),
        HRC_PKI_DIR=str(scratch / "pki"),
        HRC_SIM_STATE_DIR=str(scratch / "cobots"),
    )
    return environment


@pytest.fixture(scope="module")
def scratch(tmp_path_factory: pytest.TempPathFactory) -> Path:
    # One embedded database for the module: the first run creates and migrates it (its
    # folder does not exist yet), the others find it ready.
    return tmp_path_factory.mktemp("embedded")


def cases_for(path: Path) -> int:
    """Two cases of a thesis example, one of a use case; the extended spot taping's queue
    variant has one per operator, as the README runs it (the thesis' one has both in one)."""
    if path.stem == "2b_extended_spot_taping_queue_variant":
        return 2
    return 1 if path.parent.name == "use_cases" else 2


def run_and_check(path: Path, environment: dict[str, str], cases: int) -> float:
    """Runs `manage.py run_pattern path --simulate --json` in a child process with `environment`;
    checks that every case completed with a constraint-true trace; returns the seconds taken."""
    elapsed, _ = run_and_trace(path, environment, cases)
    return elapsed


def run_and_trace(path: Path, environment: dict[str, str], cases: int) -> tuple[float, list[Event]]:
    """run_and_check, returning the run's events as well."""
    started = time.monotonic()
    result = subprocess.run(
        [
            sys.executable,
            "manage.py",
            "run_pattern",
            str(path),
            "--simulate",
            "--json",
            "--cases",
            str(cases),
            "--time-scale",
            "0.02",
            "--seed",
            "7",
            "--timeout",
            "120",
        ],
        cwd=ROOT,
        env=environment,
        capture_output=True,
        text=True,
        timeout=180,
    )
    elapsed = time.monotonic() - started

    assert result.returncode == 0, result.stderr[-3000:]
    assert "database is locked" not in result.stderr
    assert "Traceback" not in result.stderr, result.stderr[-3000:]
    events: list[Event] = [json.loads(line) for line in result.stdout.splitlines()]
    assert {e["event"] for e in events} <= EVENTS
    numbers = {e["case"] for e in events}
    assert len(numbers) == cases, events[-3:]
    pattern = read_pattern(json.loads(path.read_text()))
    for case in numbers:
        trace = [e for e in events if e["case"] == case]
        assert trace[-1]["event"] == "case-completed", trace[-3:]
        check_trace(pattern, trace)
        check_messages(trace)
    return elapsed, events


def check_messages(trace: list[Event]) -> None:
    """A case's messages to itself: each received one was sent before, by name, and none is
    left over."""
    sent_here = {event["message"] for event in trace if event["event"] == "message-sent"}
    unread: Counter[str] = Counter()
    for event in trace:
        if event["event"] == "message-sent":
            unread[event["message"]] += 1
        elif event["event"] == "message-received" and event["message"] in sent_here:
            assert unread[event["message"]] > 0, f"received before it was sent: {event}"
            unread[event["message"]] -= 1
    assert not +unread, f"sent, never received: {+unread}"


@pytest.mark.parametrize("path", FILES, ids=[p.relative_to(EXAMPLES).as_posix() for p in FILES])
def test_each_example_and_use_case_completes_on_the_embedded_default(
    path: Path, scratch: Path
) -> None:
    cases = cases_for(path)

    elapsed = run_and_check(path, embedded_environment(scratch), cases)

    print(f"{path.name}: {cases} case(s) in {elapsed:.1f} s")


def test_a_timer_cancelling_a_running_step_completes_on_the_embedded_default(
    scratch: Path, tmp_path: Path
) -> None:
    """SQLite and the command's own threads: the deadline rings while the pick runs, as on
    PostgreSQL with workers (test_run_pattern.py)."""
    path = tmp_path / "deadline.json"
    path.write_text(json.dumps(patterns.pick_with_deadline("PT0.5S")))

    result = subprocess.run(
        [sys.executable, "manage.py", "run_pattern", str(path), "--simulate", "--json",
         "--time-scale", "0.5", "--seed", "1", "--timeout", "120"],
        cwd=ROOT, env=embedded_environment(scratch), capture_output=True, text=True, timeout=180,
    )  # fmt: skip

    assert result.returncode == 0, result.stderr[-3000:]
    assert "Traceback" not in result.stderr, result.stderr[-3000:]
    trace = [(e["event"], e["task"]) for e in map(json.loads, result.stdout.splitlines())]
    assert ("timer-fired", "late") in trace
    assert ("task-cancelled", "tc1") in trace
    assert ("task-completed", "tc1") not in trace
    assert trace[-1] == ("case-completed", None)
