"""The prediction (hrc.engine.prediction) against the runtime it predicts: the same small
patterns, with the operators' delay fixed and the cobot steps timed by the simulator's
plans, run by `run_pattern --simulate` on simulated gateways and predicted; each case's
events come in an order the prediction allows (simultaneous predicted events in any order),
and the cases end when predicted, give or take the runtime's hops between tasks."""

from __future__ import annotations

import datetime as dt
from pathlib import Path

import pytest

from hrc.cases.simulation import Simulation
from hrc.engine import read_pattern
from hrc.engine.durations import Fixed
from hrc.engine.prediction import Scenario, predict
from hrc.engine.runtime import CaseNet
from hrc_gateway.sim.timing import SimulatedPlant
from tests.cases.patterns import PICK, PROGRAM, lanes_document

pytestmark = pytest.mark.django_db(transaction=True)

TIME_SCALE = 0.5
# Seconds before the time scale (0.65 s a task): a case's events that are not simultaneous
# are then 0.3 s apart or more, well over the runtime's hops.
OPERATOR_DELAY = 1.3
# An AND split into a cobot lane (two 2 s picks) and an operator lane, joined.
COBOT_TASKS = ("tc0", "tc1")
OPERATOR_TASKS = ("to0", "to1", "to2")
# What the runtime's hops between tasks (a doorbell, a worker's lease, a tablet's poll, a
# pause and a resume sent to the cobot) may add to a case's cycle over the prediction's, at
# most, on a test machine busy with other tests; the prediction's error on a quiet machine is
# measured by `make bench`. A run is never shorter than its prediction, bar clock rounding.
HOPS = 1.5
ROUNDING = 0.1


@pytest.mark.parametrize(
    "constraints",
    [
        # to1 after tc0 has completed; the cobot holds tc1's part until to2 is done.
        [("tc0", "to1", "time"), ("tc1", "to2", "func")],
        # to1 enters the area while tc0 runs: the cobot is paused until to1 is done.
        [("tc0", "to1", "space")],
    ],
    ids=["time-and-func", "space"],
)
def test_two_cases_on_one_cobot_run_in_an_order_the_prediction_allows(
    tmp_path: Path, constraints: list[tuple[str, str, str]]
) -> None:
    document = lanes_document([list(COBOT_TASKS), list(OPERATOR_TASKS)], constraints)
    pick = {"program": PROGRAM, "number": PICK, "workspace": 0, "poses": [0.0] * 12}
    step = SimulatedPlant().seconds("c", pick, 0.0)
    assert step is not None
    times = {task: Fixed(step * TIME_SCALE) for task in COBOT_TASKS}
    times |= {task: Fixed(OPERATOR_DELAY * TIME_SCALE) for task in OPERATOR_TASKS}
    scenario = Scenario(
        cases=2, parallel=2, durations=times, people={"o": None}, variants=(), trace=True
    )
    predicted = predict(CaseNet(read_pattern(document)), scenario)
    delay = (OPERATOR_DELAY, OPERATOR_DELAY)

    with Simulation(document, tmp_path, time_scale=TIME_SCALE, operator_delay=delay) as run:
        events = run.run(2, timeout=120)

    cases = sorted({event.case for event in events})
    when: dict[tuple[int, str, str | None], float] = {
        (e.case, e.event, e.task): e.at for e in predicted.trace
    }
    names = {"task-started": "start", "task-completed": "complete"}
    for index, case in enumerate(cases):
        ran = [e for e in events if e.case == case and e.event in names]
        expected = [when[(index, names[e.event], e.task)] for e in ran]
        assert len(ran) == sum(1 for e in predicted.trace if e.case == index)
        assert expected == sorted(expected), [(e.event, e.task) for e in ran]
    start = min(dt.datetime.fromisoformat(e.at) for e in events)
    ends = [
        (dt.datetime.fromisoformat(e.at) - start).total_seconds()
        for e in events
        if e.event == "case-completed"
    ]
    assert predicted.cycle_time is not None
    assert predicted.span_seconds - ROUNDING <= max(ends) <= predicted.span_seconds + HOPS
