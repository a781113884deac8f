"""`manage.py run_pattern --simulate` as a command on PostgreSQL and Redis: the use cases in a child
process on the tests' database (the thesis examples run through the same command in-process in
test_run_pattern.py, the use cases on Celery workers in test_use_cases.py), each completing with
constraint-true traces, as test_run_pattern_embedded.py checks them on the embedded default."""

from __future__ import annotations

import itertools
from collections import Counter
from pathlib import Path

import pytest
from django.conf import settings
from django.db import connection

from hrc.cases.choices import CaseStatus
from hrc.cases.models import Case
from tests.cases.test_run_pattern import Event
from tests.cases.test_run_pattern_embedded import (
    EXAMPLES,
    cases_for,
    embedded_environment,
    run_and_check,
    run_and_trace,
)

USE_CASES = sorted((EXAMPLES / "use_cases").glob("*.json"))


def postgresql_environment(scratch: Path) -> dict[str, str]:
    """The command's environment on this test's PostgreSQL database and the tests' Redis."""
    database = settings.DATABASES["default"]
    password = f":{database['PASSWORD']}" if database["PASSWORD"] else ""
    url = (
        f"postgres://{database['USER']}{password}@{database['HOST']}:{database['PORT']}/"
        f"{connection.settings_dict['NAME']}"
    )
    assert settings.REDIS_URL, "the tests run on Redis"
    return embedded_environment(scratch) | {"DATABASE_URL": url, "REDIS_URL": settings.REDIS_URL}


@pytest.mark.django_db(transaction=True)
@pytest.mark.parametrize("path", USE_CASES, ids=[p.stem for p in USE_CASES])
def test_each_use_case_completes_through_run_pattern_on_postgresql_and_redis(
    path: Path, tmp_path: Path
) -> None:
    cases = cases_for(path)

    elapsed = run_and_check(path, postgresql_environment(tmp_path), cases)

    # They ran here, not on a SQLite file of their own.
    assert Case.objects.filter(status=CaseStatus.COMPLETED).count() == cases
    assert not (tmp_path / "var" / "hrc.sqlite3").exists()
    print(f"{path.name}: {cases} case(s) in {elapsed:.1f} s")


@pytest.mark.django_db(transaction=True)
def test_the_extended_spot_taping_keeps_its_two_processes_in_step_by_messages(
    tmp_path: Path,
) -> None:
    path = EXAMPLES / "use_cases" / "2_extended_spot_taping.json"

    _, events = run_and_trace(path, postgresql_environment(tmp_path), cases=1)

    # run_and_trace checked the constraints and that each message was sent before it was
    # received; here what the messages are for.
    [case] = Case.objects.all()
    assert case.status == CaseStatus.COMPLETED
    assert (case.data["cycle_1"], case.data["cycle_2"]) == (2, 2)
    assert (case.data["harnesses_1"], case.data["harnesses_2"]) == (4, 4)
    done = Counter(e["task"] for e in events if e["event"] == "task-completed")
    for process in ("p1", "p2"):  # both processes ran both cycles to their end
        assert done[f"{process}_to_remove_R"] == 1
        assert all(done[f"{process}_tc_tape_{spot}"] == 2 for spot in ("L1", "R1", "L2", "R2"))
    _no_two_steps_at_once_on_a_cobot(events)
    received = [e for e in events if e["event"] == "message-received"]
    assert Counter(e["message"] for e in received) == {
        **{f"p{p}_sync{n}": 2 for p in (1, 2) for n in (1, 2, 3)},
        "p1_sync4": 1, "p2_sync4": 1,  # only between the cycles
        "last_cycle": 2,
    }  # fmt: skip
    _operator_2_waits_for_the_last_cycle_decision(events)


def _no_two_steps_at_once_on_a_cobot(events: list[Event]) -> None:
    running: dict[str, str | None] = {}
    served: dict[str, list[str]] = {}
    for event in events:
        if event["actor"] not in ("c1", "c2"):
            continue
        cobot, task = event["actor"], event["task"]
        if event["event"] == "task-started":
            assert running.get(cobot) is None, f"{cobot} runs {running[cobot]} and {task}"
            running[cobot] = task
            if "_tape_" in task:
                served.setdefault(cobot, []).append(task[:2])
        elif event["event"] == "task-completed":
            running[cobot] = None
    # Each cobot tapes for both operators, four spots each, taking turns.
    for cobot, processes in served.items():
        assert Counter(processes) == {"p1": 4, "p2": 4}, (cobot, processes)
        assert all(a != b for a, b in itertools.pairwise(processes)), (cobot, processes)


def _operator_2_waits_for_the_last_cycle_decision(events: list[Event]) -> None:
    """Operator 2's process goes past the end of a cycle only with operator 1's decision."""
    decisions = [i for i, e in enumerate(events) if e["task"] == "p2_x_last_cycle"]
    decided = [i for i, e in enumerate(events) if e["task"] == "p1_to_remove_L"
               and e["event"] == "task-completed"]  # fmt: skip
    ends = [i for i, e in enumerate(events) if e["event"] == "task-started"
            and e["task"] in ("p2_to_wires_L_again", "p2_to_remove_R")]  # fmt: skip
    assert len(decisions) == len(decided) == len(ends) == 2
    for decision, sent, end in zip(decisions, decided, ends, strict=True):
        assert sent < decision < end
