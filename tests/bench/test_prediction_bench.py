"""The prediction benchmark's own arithmetic: which tasks get the operators' time, the
calibration's costs, the run's draws replayed, the options, and the speed row against its
floor."""

import json
import random

import pytest

from bench.prediction import (
    OPERATOR_TIME,
    QUICK,
    Calibration,
    Draws,
    Settings,
    _CalibratedPlant,
    cobot_shares,
    median_interval,
    operator_durations,
    parse_args,
    predicted,
    speed,
)
from bench.use_cases import use_case_files
from hrc.engine import read_pattern
from hrc.engine.durations import Triangular
from hrc.engine.runtime import CaseNet
from hrc_gateway.sim import sensors
from hrc_gateway.sim.timing import CHECK_PLACE, WAIT_PLACE, SimulatedPlant
from tests.cases.patterns import PICK, PROGRAM, cobot_chain


def test_every_operator_task_and_only_those_take_the_operators_time_shifted_by_its_cost() -> None:
    net = CaseNet(read_pattern(cobot_chain(steps=2)))

    assert operator_durations(net) == {"to1": OPERATOR_TIME}
    assert operator_durations(net, Calibration(hop=0.5)) == {"to1": OPERATOR_TIME}  # a handover
    costs = Calibration(hop=0.5, operator=0.25)
    assert operator_durations(net, costs) == {"to1": Triangular(2.25, 4.25, 8.25)}


def test_the_calibrated_plant_adds_the_step_or_call_cost_to_each_command() -> None:
    pick = {"program": PROGRAM, "number": PICK, "workspace": 0, "poses": [0.0] * 12}
    scan = {"method": "Devices/PartDetection/Scan", "args": [], "outputs": ["detected", "pose"]}
    plain = SimulatedPlant().seconds("c", pick, 0.0)
    costs = Calibration(hop=0.25, step=0.5, call=0.125)

    assert plain is not None
    assert _CalibratedPlant(costs).seconds("c", pick, 0.0) == pytest.approx(plain + 0.5)
    assert _CalibratedPlant(costs).seconds("c.part-detection", scan, 0.0) == pytest.approx(2.125)
    assert _CalibratedPlant(costs).seconds("c", {**pick, "program": "none"}, 0.0) is None


def test_the_runs_device_answers_are_given_in_call_order_per_cobot_then_the_odds() -> None:
    scan = {"method": "Devices/PartDetection/Scan", "args": [], "outputs": ["detected", "pose"]}
    found, none = {"detected": True, "pose": [0.1] * 6}, {"detected": False, "pose": [0.0] * 6}
    draws = Draws({}, {("c", "Devices/PartDetection/Scan"): [found, none, found]})
    plant = _CalibratedPlant(Calibration(), draws)
    rng = random.Random(3)

    answers = [plant.answer("c.part-detection", scan, rng, 0.0) for _ in range(3)]
    untouched = rng.getstate() == random.Random(3).getstate()  # nothing drawn meanwhile
    other = plant.answer("c2.part-detection", scan, random.Random(3), 0.0)
    after = plant.answer("c.part-detection", scan, rng, 0.0)

    assert answers == [found, none, found]
    assert untouched
    assert other == SimulatedPlant().answer("c2", scan, random.Random(3), 0.0)
    assert after == SimulatedPlant().answer("c", scan, random.Random(3), 0.0)


def test_a_replayed_occupied_place_makes_the_next_wait_last_until_it_clears() -> None:
    check = {"method": CHECK_PLACE, "args": [], "outputs": ["free"]}
    wait = {"method": WAIT_PLACE, "args": [60000], "outputs": ["free"]}
    plant = _CalibratedPlant(Calibration(), Draws({}, {("c", CHECK_PLACE): [{"free": False}]}))

    assert plant.answer("c.place-position", check, random.Random(0), 10.0) == {"free": False}
    assert plant.seconds("c.place-position", wait, 12.0) == pytest.approx(
        sensors.CLEARS_AFTER_SECONDS - 2
    )


def test_replayed_operator_times_come_in_start_order_then_the_distribution() -> None:
    net = CaseNet(read_pattern(cobot_chain(steps=2)))
    rng = random.Random(5)

    costs = Calibration(hop=0.5, operator=0.25)
    replayed = operator_durations(net, costs, Draws({"to1": [3.0, 7.0]}, {}))["to1"]

    # The run's times hold the operator's cost already, and the hop is the handover's.
    assert [replayed.sample(rng), replayed.sample(rng)] == [3.0, 7.0]
    assert 2.25 <= replayed.sample(rng) <= 8.25
    assert replayed.mean == pytest.approx(Triangular(2.25, 4.25, 8.25).mean)


def test_a_replayed_prediction_of_a_chain_takes_the_runs_operator_times() -> None:
    net = CaseNet(read_pattern(cobot_chain(steps=2)))
    plain = predicted(net, 1, 2, draws=Draws({"to1": [10.0, 20.0]}, {}))
    steps = 2 * SimulatedPlant().seconds("c", {"program": PROGRAM, "number": PICK, "workspace": 0, "poses": [0.0] * 12}, 0.0)  # type: ignore[operator]  # fmt: skip

    assert plain.cycle_time is not None
    assert (plain.cycle_time.min, plain.cycle_time.max) == pytest.approx(
        (10 + steps, 20 + steps), abs=0.5
    )


def test_a_cobots_utilisation_leaves_out_the_handover_before_its_steps() -> None:
    net = CaseNet(read_pattern(cobot_chain(steps=2)))
    plain, calibrated = predicted(net, 1, 50), predicted(net, 1, 50, Calibration(hop=0.5))

    (busy,) = [load for load in calibrated.actors if load.kind == "cobot"]
    share = cobot_shares(calibrated, 0.5)[busy.actor]
    span = busy.busy_seconds / busy.utilisation

    assert share == pytest.approx((busy.busy_seconds - 0.5 * busy.work_items) / span)
    assert share < busy.utilisation
    assert cobot_shares(plain, 0.0) == {load.actor: load.utilisation for load in plain.actors if load.kind == "cobot"}  # fmt: skip


def test_the_median_interval_holds_the_median_and_narrows_with_more_cases() -> None:
    rng = random.Random(1)
    few = [rng.expovariate(0.1) for _ in range(5)]
    many = [rng.expovariate(0.1) for _ in range(500)]

    low, high = median_interval(few)
    assert low <= sorted(few)[2] <= high
    narrow = median_interval(many)
    assert narrow[1] - narrow[0] < (high - low) / 2


def test_a_calibrated_prediction_of_a_chain_is_longer_by_a_hop_per_task() -> None:
    net = CaseNet(read_pattern(cobot_chain(steps=2)))

    plain, calibrated = predicted(net, 1, 50), predicted(net, 1, 50, Calibration(hop=0.5))

    assert plain.cycle_time is not None
    assert calibrated.cycle_time is not None
    assert calibrated.cycle_time.mean == pytest.approx(plain.cycle_time.mean + 3 * 0.5)


def test_the_speed_row_times_the_largest_use_case_against_a_bare_loop() -> None:
    row = speed(20)

    largest = max(
        (CaseNet(read_pattern(json.loads(path.read_text()))) for path in use_case_files()),
        key=lambda net: sum(1 for _, t in net.pattern.transitions() if t.performer),
    )
    assert row["use_case"] == largest.pattern.name
    assert row["cases"] == 20
    assert row["events"] >= 2 * 20  # each case starts and completes a task at least
    assert row["seconds"] > row["floor_seconds"] > 0


def test_quick_sets_the_small_sizes() -> None:
    assert parse_args([]) == Settings()
    assert parse_args(["--quick"]).rounds == QUICK["rounds"]
    assert parse_args(["--quick", "--rounds", "3"]).rounds == 3
