"""`manage.py run_pattern --simulate`: every thesis example runs to completion, and its trace keeps
every constraint as pattern-format.md defines it at run time."""

from __future__ import annotations

import datetime as dt
import io
import json
from collections import Counter
from pathlib import Path
from typing import Any

import pytest
from django.core.management import CommandError, call_command

from hrc.cases.models import CaseEvent
from hrc.engine.bpmn import bpmn_to_document
from hrc.engine.document import read_pattern
from hrc.engine.execution import supporter_of
from hrc.engine.model import Pattern
from hrc.engine.runtime import CaseNet
from tests.cases import patterns
from tests.engine.test_completion import PARALLEL_ENDS

EXAMPLES = sorted((Path(__file__).parents[2] / "hrc" / "patterns" / "examples").glob("*.json"))
EVENTS = {
    "task-started",
    "task-completed",
    "task-interrupted",
    "task-resumed",
    "case-completed",
    "case-failed",
    "message-sent",
    "message-received",
}

Event = dict[str, Any]


def run_pattern(path: Path, *options: str) -> list[Event]:
    out = io.StringIO()
    call_command("run_pattern", str(path), "--simulate", "--json", *options, stdout=out)
    return [json.loads(line) for line in out.getvalue().splitlines()]


@pytest.mark.django_db(transaction=True)
@pytest.mark.parametrize("path", EXAMPLES, ids=[p.stem for p in EXAMPLES])
def test_each_example_runs_to_completion_keeping_its_constraints(path: Path) -> None:
    events = run_pattern(path, "--cases", "3", "--time-scale", "0.02", "--seed", "7")
    pattern = read_pattern(json.loads(path.read_text()))

    assert [e["seq"] for e in events] == list(range(1, len(events) + 1))
    assert all(set(e) == {"seq", "at", "case", "task", "actor", "event"} for e in events)
    assert {e["event"] for e in events} <= EVENTS
    cases = {e["case"] for e in events}
    assert len(cases) == 3
    for case in cases:
        trace = [e for e in events if e["case"] == case]
        assert trace[-1]["event"] == "case-completed"
        check_trace(pattern, trace)


def check_trace(pattern: Pattern, trace: list[Event]) -> None:
    """Each task runs start-to-completion; time, func and space hold at every event."""
    started: Counter[str] = Counter()
    completed: Counter[str] = Counter()
    interrupted: set[str] = set()
    space_rules = CaseNet(pattern).space_rules
    for event in trace:
        task, kind = event["task"], event["event"]
        if kind == "task-started":
            for c in pattern.constraints:
                if c.type == "time" and c.target == task:
                    assert completed[c.source] > started[task], f"time {c.source}→{task}: {event}"
                if c.type == "func" and supporter_of(pattern, c)[1] == task:
                    supporter = supporter_of(pattern, c)[0]
                    assert started[supporter] > completed[supporter], (
                        f"func: {supporter} not running"
                    )
            for rule in space_rules(task):
                occupant = rule.by if rule.held == task else rule.held
                if started[occupant] == completed[occupant]:
                    continue  # the other task is not in the area
                # The task kept out never starts beside the other; a cobot interrupted is so
                # from the moment both are in the area (one transaction: adjacent events).
                assert not rule.keeps_out, f"{task} started beside {occupant}: {event}"
                assert rule.held in interrupted or _next_is_interruption(trace, event, rule.held)
            started[task] += 1
        elif kind == "task-completed":
            assert started[task] == completed[task] + 1, f"{task} completed without running"
            for c in pattern.constraints:
                if c.type == "func" and supporter_of(pattern, c)[0] == task:
                    supported = supporter_of(pattern, c)[1]
                    assert completed[supported] == started[supported] > 0, (
                        f"func: {supported} not done"
                    )
            completed[task] += 1
            interrupted.discard(task)
        elif kind == "task-interrupted":
            assert started[task] == completed[task] + 1, "only a running cobot task is interrupted"
            interrupted.add(task)
        elif kind == "task-resumed":
            interrupted.discard(task)
    assert started == completed
    assert started
    assert set(started) <= {t.id for _, t in pattern.transitions() if t.is_task}


def _next_is_interruption(trace: list[Event], event: Event, cobot_task: str) -> bool:
    """A start and the interruption it causes are one transaction: adjacent events."""
    after = trace[trace.index(event) + 1 :]
    return any(e["event"] == "task-interrupted" and e["task"] == cobot_task for e in after[:3])


@pytest.mark.django_db(transaction=True)
def test_the_quality_inspection_keeps_its_operators_and_their_cobots_apart() -> None:
    """The thesis' quality inspection: o1 and o2 share an area (to12, to21), each beside a cobot."""
    path = next(p for p in EXAMPLES if p.stem == "coop_2o2c_quality_inspection")
    events = run_pattern(path, "--cases", "2", "--time-scale", "0.02", "--seed", "3")
    pattern = read_pattern(json.loads(path.read_text()))

    for case in {e["case"] for e in events}:
        trace = [e for e in events if e["case"] == case]
        assert trace[-1]["event"] == "case-completed"
        check_trace(pattern, trace)
        assert not _overlapping(trace, "to12", "to21")


def _overlapping(trace: list[Event], one: str, other: str) -> bool:
    """Whether the two tasks ever ran at once in the trace."""
    running: set[str] = set()
    for event in trace:
        if event["task"] not in (one, other):
            continue
        if event["event"] == "task-started":
            running.add(event["task"])
            if running == {one, other}:
                return True
        elif event["event"] == "task-completed":
            running.discard(event["task"])
    return False


@pytest.mark.django_db(transaction=True)
def test_a_cooperation_with_a_space_constraint_records_its_interruptions() -> None:
    path = next(p for p in EXAMPLES if p.stem == "coop_1o1c_polishing")
    events = run_pattern(path, "--cases", "4", "--time-scale", "0.05", "--seed", "3")

    kinds = Counter(e["event"] for e in events)
    assert kinds["case-completed"] == 4
    assert kinds["task-interrupted"] == kinds["task-resumed"]


@pytest.mark.django_db
def test_a_file_that_does_not_check_names_its_errors(tmp_path: Path) -> None:
    broken = tmp_path / "broken.json"
    broken.write_text(
        json.dumps({"format": "hrc-pattern/1", "name": "x", "actors": [], "processes": []})
    )

    with pytest.raises(CommandError, match="cannot run"):
        run_pattern(broken)
    with pytest.raises(CommandError, match="Cannot read"):
        run_pattern(tmp_path / "missing.json")


@pytest.mark.django_db(transaction=True)
def test_an_imported_bpmn_process_whose_branches_end_apart_completes(tmp_path: Path) -> None:
    # BPMN's implicit completion: each branch of the parallel split ends at its own end event.
    path = tmp_path / "parallel-ends.json"
    path.write_text(json.dumps(bpmn_to_document(PARALLEL_ENDS)))

    events = run_pattern(path, "--cases", "2", "--time-scale", "0", "--seed", "5")

    cases = {e["case"] for e in events}
    assert len(cases) == 2
    for case in cases:
        trace = [e["event"] + " " + (e["task"] or "") for e in events if e["case"] == case]
        assert sorted(trace[:-1]) == [
            "task-completed a",
            "task-completed b",
            "task-started a",
            "task-started b",
        ]
        assert trace[-1].startswith("case-completed")


@pytest.mark.django_db(transaction=True)
def test_a_timer_rings_and_cancels_a_running_step_in_a_simulated_run(tmp_path: Path) -> None:
    """The deadline (an hour, times the timer scale: 0.36 s) passes while the cobot's pick (2 s,
    times the time scale: 1 s) runs: the pick is cancelled but runs to its end on the cobot,
    which only then puts the part back."""
    path = tmp_path / "deadline.json"
    path.write_text(json.dumps(patterns.pick_with_deadline("PT1H")))

    events = run_pattern(path, "--time-scale", "0.5", "--timer-scale", "0.0001", "--seed", "1")

    trace = [(e["event"], e["task"]) for e in events]
    assert trace[-1] == ("case-completed", None)
    assert ("timer-fired", "late") in trace
    assert ("task-cancelled", "tc1") in trace
    assert ("task-started", "tc1") in trace
    assert ("task-completed", "tc1") not in trace
    assert ("task-completed", "to_clear") in trace
    assert ("task-completed", "tc2") in trace
    [case] = {e["case"] for e in events}
    log = CaseEvent.objects.filter(case_id=case).order_by("seq")
    ended = log.get(type="cancelled-step-ended", task="tc1")
    assert ended.detail["result"]["outcome"] == "ran"
    assert ended.seq < log.get(type="task-started", task="tc2").seq


def _two_operator_tasks() -> dict[str, Any]:
    """One operator: `first`, then `second`."""
    tasks = [{"id": "first", "performer": "o"}, {"id": "second", "performer": "o"}]
    arcs = [["p0", "first"], ["first", "p1"], ["p1", "second"], ["second", "p2"]]
    document = patterns._document("Two tasks", patterns._process(tasks, arcs, ["p0", "p1", "p2"]), [])  # fmt: skip
    document["actors"] = [{"id": "o", "type": "operator"}]
    document["processes"][0]["actors"] = ["o"]
    return document


@pytest.mark.django_db(transaction=True)
def test_operators_take_the_times_durations_give_their_tasks(tmp_path: Path) -> None:
    """2 s and 6 s at a time scale of 0.1: 0.2 s and 0.6 s of wall time, where without the file
    each would take 0.02–0.1 s."""
    path = tmp_path / "two.json"
    path.write_text(json.dumps(_two_operator_tasks()))
    durations = tmp_path / "durations.json"
    durations.write_text(
        json.dumps(
            {
                "first": {"kind": "fixed", "seconds": 2},
                "second": {"kind": "triangular", "low": 6, "mode": 6, "high": 6},
            }
        )
    )

    events = run_pattern(path, "--time-scale", "0.1", "--durations", str(durations))

    at = {(e["event"], e["task"]): dt.datetime.fromisoformat(e["at"]) for e in events}
    took = {
        task: (at[("task-completed", task)] - at[("task-started", task)]).total_seconds()
        for task in ("first", "second")
    }
    assert 0.2 <= took["first"] < 0.45
    assert 0.6 <= took["second"] < 0.85


@pytest.mark.django_db
@pytest.mark.parametrize(
    ("durations", "complaint"),
    [
        ([], "must be an object of task id"),
        ({"nobody": {"kind": "fixed", "seconds": 1}}, "'nobody' is not an operator's task"),
        ({"first": {"kind": "uniform"}}, "first: a time's 'kind' is fixed, triangular"),
        ({"first": {"kind": "fixed", "seconds": -1}}, "first: seconds must be"),
    ],
)
def test_durations_that_are_not_operator_tasks_times_are_refused(
    tmp_path: Path, durations: object, complaint: str
) -> None:
    path = tmp_path / "two.json"
    path.write_text(json.dumps(_two_operator_tasks()))
    times = tmp_path / "durations.json"
    times.write_text(json.dumps(durations))

    with pytest.raises(CommandError, match=complaint):
        run_pattern(path, "--durations", str(times))
    with pytest.raises(CommandError, match="Cannot read"):
        run_pattern(path, "--durations", str(tmp_path / "missing.json"))
