"""What the prediction benchmark reads from a real run: the run's draws (operator times, device
answers), its runtime costs and its cobots' utilisation, on use case 3 (a loop that chance
decides) run against a simulated gateway; replayed, the prediction takes the run's path."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from bench.prediction import (
    OPERATOR_TIME,
    cobot_busy,
    operator_durations,
    predicted,
    recorded,
)
from bench.use_cases import use_case_files
from hrc.cases.models import WorkItem
from hrc.cases.simulation import Simulation
from hrc.engine import read_pattern
from hrc.engine.runtime import CaseNet

pytestmark = pytest.mark.django_db(transaction=True)

SCALE = 0.1
SCAN = "Devices/PartDetection/Scan"


def test_a_replayed_prediction_loops_as_often_as_the_run_did(tmp_path: Path) -> None:
    (path,) = use_case_files(("3",))
    document = json.loads(path.read_text())
    net = CaseNet(read_pattern(document))
    with Simulation(
        document, tmp_path, time_scale=SCALE, inline=True, seed=11, durations=operator_durations(net)
    ) as simulation:  # fmt: skip
        with simulation.running():
            ids = simulation.start_cases(1)
            assert simulation.wait(ids, timeout=120)
        draws, costs = recorded(ids, SCALE, f"-{simulation.organisation.slug}")
        span, busy = cobot_busy(simulation, ids)
    scans = WorkItem.objects.filter(case_id__in=ids, task="tc_scan").count()

    answers = draws.answers[("c", SCAN)]
    assert len(answers) == scans
    assert [answer["detected"] for answer in answers] == [True] * (scans - 1) + [False]
    assert set(draws.operator_times) == {"to_check_box", "to_box_aside", "to_new_box"}
    assert all(2 <= t[0] <= 9 and len(t) == 1 for t in draws.operator_times.values())
    assert 0 < costs.step < 2  # a handshake, not a step's motion
    assert 0 <= costs.call < 2
    took = [t for times in draws.operator_times.values() for t in times]
    assert costs.operator == pytest.approx(sum(took) / len(took) - OPERATOR_TIME.mean)
    assert set(busy) == {"c"}
    assert 0 < busy["c"] < span

    replayed = predicted(net, 1, 1, costs, draws)
    (scan,) = [task for task in replayed.tasks if task.task == "tc_scan"]
    assert scan.runs == scans
