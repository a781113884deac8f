"""The prediction (hrc.engine.prediction) against `run_pattern --simulate`: the same small
patterns, given fixed times (the operators' through the simulation's `durations`, the cobots'
from the simulator's programs at a time scale), give each case the same sequence of task
starts and completions, run through the real Simulation (inline jobs, real OPC UA gateway
processes) and predicted with the same times and the simulator's plant. A run never ends
before its prediction; how much later it ends on a quiet machine is `make bench`'s figure.

Events the prediction puts at one instant (a completion and the starts it enables, an AND
split's first tasks) happen at run time a few hops apart in an order nobody decides (a
worker's lease against a tablet's poll), so they are compared as a set: the prediction's
events are cut into instants, and the run's, in the order its log recorded them, into runs of
the same lengths. However long the hops take on a busy machine, each instant's events must
then come together, in the instant's place. The times are chosen so that the prediction's
distinct instants are MIN_GAP or more apart (the test checks it first), far over the
runtime's hops: the run's order then says what hrc did, not who won a race.
"""

from __future__ import annotations

import datetime as dt
import itertools
from pathlib import Path

import pytest

from hrc.cases.simulation import RunEvent, Simulation
from hrc.engine import read_pattern
from hrc.engine.durations import Fixed
from hrc.engine.prediction import Scenario, predict
from hrc.engine.prediction_report import TraceEvent
from hrc.engine.runtime import CaseNet
from hrc_gateway.sim.timing import SimulatedPlant
from tests.cases.patterns import lanes_document

pytestmark = pytest.mark.django_db(transaction=True)

# Wall seconds per simulated second, for the cobots' programs and the operators alike: a 2 s
# pick takes about 1 s.
TIME_SCALE = 0.5
# An operator's task: 4 s simulated, 2 s of wall time. With it every pattern's distinct
# instants lie 1 s of wall time apart or more (with 1.4 s some lay 0.3 s apart).
OPERATOR_SECONDS = 4.0
# A space constraint pauses the cobot only when the operator's task enters the area while the
# cobot's task runs: there to0 takes 1 s and the pick 2 s of wall time (time scale 1), so to1
# starts a second into the pick, and the pause has that second to reach the cobot.
SPACE_SECONDS = {"to0": 1.0}
SPACE_TIME_SCALE = 1.0
# The prediction's distinct instants at least this far apart (wall seconds). The hops between
# a completion and what it starts are tens of milliseconds on a quiet machine, but under the
# test suite's load (two test processes, their gateways and workers) an operator's task once
# started more than 0.3 s after the completion that enabled it, and the run's order then said
# who won a race.
MIN_GAP = 0.9

Instant = frozenset[tuple[str, str]]


def _predicted_instants(
    trace: tuple[TraceEvent, ...], case: int, time_scale: float
) -> list[Instant]:
    """The case's events by instant, in time order; fails if two instants lie too close."""
    instants: dict[float, set[tuple[str, str]]] = {}
    for event in trace:
        if event.case == case:
            instants.setdefault(event.at, set()).add((event.task, event.event))
    times = sorted(instants)
    gaps = [(b - a) * time_scale for a, b in itertools.pairwise(times)]
    assert all(gap >= MIN_GAP for gap in gaps), f"instants too close to compare: {times}"
    return [frozenset(instants[at]) for at in times]


def _run_instants(events: list[RunEvent], case: int, sizes: list[int]) -> list[Instant]:
    """The case's events in log order, cut into runs of `sizes` (the predicted instants')."""
    names = {"task-started": "start", "task-completed": "complete"}
    ran = [(e.task or "", names[e.event]) for e in events if e.case == case and e.event in names]
    assert len(ran) == sum(sizes), ran
    cuts = list(itertools.accumulate(sizes, initial=0))
    return [frozenset(ran[start:end]) for start, end in itertools.pairwise(cuts)]


SPACE = [("tc0", "to1", "space")]
TIME_AND_FUNC = [("tc0", "to1", "time"), ("tc1", "to2", "func")]
TWO_LANES = [["tc0", "tc1"], ["to0", "to1", "to2"]]


@pytest.mark.parametrize(
    ("lanes", "constraints", "cases", "seconds", "time_scale"),
    [
        # The operator loads, the cobot picks, the operator unloads.
        ([["to1", "tc1", "to2"]], [], 1, {}, TIME_SCALE),
        # to1 waits for tc0 to complete, though its lane is free from the start.
        ([["tc0", "tc1"], ["to1", "to2"]], [("tc0", "to1", "time")], 1, {}, TIME_SCALE),
        # The cobot holds tc1's part until the operator's to2 on it is done.
        ([["tc1"], ["to1", "to2"]], [("tc1", "to2", "func")], 1, {}, TIME_SCALE),
        # to1 enters the area while tc0 runs: the cobot is paused until to1 is done.
        (TWO_LANES, SPACE, 1, SPACE_SECONDS, SPACE_TIME_SCALE),
        # Two cases, one cobot: the second case's pick waits for the first's.
        ([["tc0"], ["to0", "to1"]], [], 2, {}, TIME_SCALE),
        # Two cases, one cobot, and the first's func hold keeps the second's pick waiting.
        (TWO_LANES, TIME_AND_FUNC, 2, {}, TIME_SCALE),
        # Two cases, one cobot: the first case's to1 pauses its tc0; the second's waits behind.
        (TWO_LANES, SPACE, 2, SPACE_SECONDS, SPACE_TIME_SCALE),
    ],
    ids=[
        "sequence", "time", "func", "space", "two-cases-one-cobot",
        "two-cases-time-and-func", "two-cases-space",
    ],
)  # fmt: skip
def test_each_case_starts_and_completes_its_tasks_in_the_predicted_order(
    tmp_path: Path,
    lanes: list[list[str]],
    constraints: list[tuple[str, str, str]],
    cases: int,
    seconds: dict[str, float],
    time_scale: float,
) -> None:
    document = lanes_document(lanes, constraints)
    operator_tasks = [task for task in itertools.chain(*lanes) if task.startswith("to")]
    durations = {task: Fixed(seconds.get(task, OPERATOR_SECONDS)) for task in operator_tasks}
    scenario = Scenario(
        cases=cases, parallel=cases, durations=durations, people={"o": None}, trace=True
    )
    predicted = predict(CaseNet(read_pattern(document)), scenario, plant=SimulatedPlant)
    expected = [_predicted_instants(predicted.trace, index, time_scale) for index in range(cases)]

    with Simulation(document, tmp_path, time_scale=time_scale, durations=durations) as run:
        events = run.run(cases, timeout=120)

    started = sorted({event.case for event in events})
    assert [e.event for e in events if e.event.startswith("case-")] == ["case-completed"] * cases
    sizes = [[len(instant) for instant in instants] for instants in expected]
    assert [
        _run_instants(events, case, n) for case, n in zip(started, sizes, strict=True)
    ] == expected
    times = [dt.datetime.fromisoformat(event.at) for event in events]
    assert (max(times) - min(times)).total_seconds() >= predicted.span_seconds * time_scale - 0.1
