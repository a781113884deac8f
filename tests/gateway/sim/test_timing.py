"""The simulator's cell without running it (hrc_gateway.sim.timing): steps timed by their
plans' motion profiles from where the arm stopped, device calls by the simulator's times,
answers with its odds."""

import random

import pytest

from hrc_gateway.sim import devices, sensors
from hrc_gateway.sim.fencing import StepRequest
from hrc_gateway.sim.kinematics import HOME
from hrc_gateway.sim.programs import PROGRAMS, TOOL_SECONDS, Move
from hrc_gateway.sim.robot import MOVEJ_ACCELERATION, MOVEJ_SPEED, move_profile
from hrc_gateway.sim.timing import SimulatedPlant

NO_POSES = [0.0] * 12


def _step(
    number: int, workspace: int = 0, program: str = "Collaboration_Fixture"
) -> dict[str, object]:
    return {"program": program, "number": number, "workspace": workspace, "poses": NO_POSES}


def test_a_step_takes_its_moves_profiles_and_its_tool_waits() -> None:
    plant = SimulatedPlant()
    program = PROGRAMS["Collaboration_Fixture"]
    plan = program.plan(StepRequest((0, 0), 2, 0, tuple(NO_POSES)), HOME, {})
    expected, at = TOOL_SECONDS, HOME
    for action in plan.actions:
        if isinstance(action, Move):
            profile = move_profile(at, action.target, program.tcp, action.linear, action.speed, action.acceleration)  # fmt: skip
            expected, at = expected + profile.duration, action.target

    assert plant.seconds("c", _step(2), 0.0) == pytest.approx(expected)
    assert expected > TOOL_SECONDS


def test_a_step_starts_where_the_cobots_last_step_left_the_arm() -> None:
    plant = SimulatedPlant()
    mount = _step(3, workspace=1)

    first = plant.seconds("c", mount, 0.0)  # from home out to the mounting position
    again = plant.seconds("c", mount, 0.0)  # already there
    home = plant.seconds("c", _step(1), 0.0)  # back

    assert again == 0
    assert home == pytest.approx(first)
    assert plant.seconds("other", mount, 0.0) == pytest.approx(first)  # its own arm, at home


def test_a_step_the_simulator_refuses_or_does_not_know_has_no_time() -> None:
    plant = SimulatedPlant()

    assert plant.seconds("c", _step(9), 0.0) is None
    assert plant.seconds("c", _step(1, program="Nobody's"), 0.0) is None


def test_device_calls_take_the_simulators_times() -> None:
    plant = SimulatedPlant()

    def call(method: str, *args: object) -> float | None:
        return plant.seconds("c", {"method": method, "args": list(args), "outputs": []}, 0.0)

    assert call("Devices/LinearAxis/Move", "left", 4000) == 4
    assert call("Devices/PartDetection/Scan") == devices.SCAN_SECONDS
    assert call("Devices/Recognition/Face") == sensors.RECOGNITION_SECONDS
    assert call("Devices/Display/Show", "hello") == 0
    assert call("Devices/PlacePosition/WaitUntilFree", 60000) == 0  # nothing occupied it


def test_device_answers_come_with_the_simulators_odds_from_the_given_source() -> None:
    plant = SimulatedPlant()
    scan = {"method": "Devices/PartDetection/Scan", "args": [], "outputs": ["detected", "pose"]}
    rng = random.Random(9)

    answers = [plant.answer("c", scan, rng, 0.0) for _ in range(6000)]

    found = [a for a in answers if a and a["detected"]]
    assert len(found) / 6000 == pytest.approx(devices.DETECTION_PROBABILITY, abs=0.02)
    middle = tuple(round((low + high) / 2, 4) for low, high in devices.PART_BOX)
    assert {tuple(a["pose"]) for a in found} == {(*middle, 0.0, 0.0, 0.0)}
    assert plant.answer("c", scan, random.Random(1), 0.0) == plant.answer(
        "c", scan, random.Random(1), 0.0
    )


def test_an_occupied_place_position_clears_three_seconds_after_the_check_however_long_the_wait() -> (
    None
):
    """As sensors.PlacePosition: the wait lasts what is left of the occupation when it starts
    (the cobot moved to its wait position meanwhile), and a check before it clears sees it
    occupied without a new draw."""
    plant = SimulatedPlant()
    check = {"method": "Devices/PlacePosition/Check", "args": [], "outputs": ["free"]}
    wait = {"method": "Devices/PlacePosition/WaitUntilFree", "args": [60000], "outputs": ["free"]}
    rng = random.Random(0)
    at = 10.0
    while plant.answer("c", check, rng, at) == {"free": True}:
        at += 1

    assert plant.seconds("c", wait, at) == sensors.CLEARS_AFTER_SECONDS
    assert plant.seconds("c", wait, at + 2.5) == pytest.approx(sensors.CLEARS_AFTER_SECONDS - 2.5)
    assert plant.seconds("c", wait, at + 4) == 0
    assert plant.seconds("other", wait, at) == 0  # its own place position, never occupied
    assert plant.answer("c", wait, rng, at + 3) == {"free": True}
    state = rng.getstate()
    assert plant.answer("c", check, rng, at + 1) == {"free": False}
    assert rng.getstate() == state


def test_a_wait_ends_at_its_timeout_if_the_occupation_outlasts_it() -> None:
    plant = SimulatedPlant()
    check = {"method": "Devices/PlacePosition/Check", "args": [], "outputs": ["free"]}
    rng = random.Random(0)
    while plant.answer("c", check, rng, 0.0) == {"free": True}:
        pass
    short = {"method": "Devices/PlacePosition/WaitUntilFree", "args": [500], "outputs": ["free"]}

    assert plant.seconds("c", short, 0.0) == 0.5


def test_the_movej_speed_times_a_joint_move() -> None:
    target = (HOME[0] + 1.0, *HOME[1:])
    profile = move_profile(HOME, target, PROGRAMS["Collaboration_Fixture"].tcp, False, MOVEJ_SPEED, MOVEJ_ACCELERATION)  # fmt: skip

    assert profile.duration == pytest.approx(1.0 / MOVEJ_SPEED + MOVEJ_SPEED / MOVEJ_ACCELERATION)
