"""The simulator's cell without running it: how long a step or a device call takes, and what a
device answers, for a prediction (hrc.engine.prediction's `Plant`; the gateway imports
nothing of hrc, the shape is all they share).

A step's time is its plan's (programs.py) at full speed: each move's motion profile
(robot.move_profile) and each tool wait, from where the arm stopped after the cobot's
previous step (the home pose at first). A program's variables carry over from step to
step while the cobot stays in it. Device calls take the simulator's times and draw their
answers with the simulator's odds (devices.py, sensors.py) from the random source they
are given; a detected part lies in the middle of the part box, so that cases do not each
ask for a new pose.
"""

from __future__ import annotations

import random
from collections.abc import Mapping
from typing import Any, Final

from hrc_gateway.sim import devices, sensors
from hrc_gateway.sim.fencing import StepRequest
from hrc_gateway.sim.kinematics import HOME, Joints, Unreachable
from hrc_gateway.sim.programs import PROGRAMS, Dwell, Move, Program, Refused
from hrc_gateway.sim.robot import move_profile

CHECK_PLACE: Final = "Devices/PlacePosition/Check"
WAIT_PLACE: Final = "Devices/PlacePosition/WaitUntilFree"
# Where a detected part lies: the middle of the part box.
PART_POSE: Final = [round((low + high) / 2, 4) for low, high in devices.PART_BOX] + [0.0] * 3

_Key = tuple[str, Joints, tuple[tuple[str, int], ...], int, int, tuple[float, ...]]
_Request = tuple[Program, int, int, tuple[float, ...]]


class _Arm:
    """Where an arm stands between steps: its program, joints and variables (never changed),
    and the steps taken from there, by the id of their command (the plant keeps the commands
    it read, so ids stay theirs; a step's time and where it leaves the arm depend on nothing
    else)."""

    __slots__ = ("joints", "program", "steps", "variables")

    def __init__(self, program: str, joints: Joints, variables: dict[str, int]) -> None:
        self.program, self.joints, self.variables = program, joints, variables
        self.steps: dict[int, tuple[float, _Arm]] = {}


class SimulatedPlant:
    """The simulator's cobots and devices, one arm per cobot name; make one per prediction."""

    def __init__(self) -> None:
        self._home = _Arm("", HOME, {})  # a plant's own: its steps are by its requests' ids
        self._arms: dict[str, _Arm] = {}
        self._steps: dict[_Key, tuple[float, _Arm]] = {}
        # Cobots whose place position was seen occupied: when it clears (the prediction's
        # clock), CLEARS_AFTER_SECONDS after the check, as sensors.PlacePosition's does.
        self._clears_at: dict[str, float] = {}
        # Each command read once: a prediction asks again and again with the same objects
        # (kept here, so that their ids stay theirs).
        self._requests: dict[int, tuple[Mapping[str, Any], _Request | None]] = {}

    def seconds(self, cobot: str, command: Mapping[str, Any], at: float) -> float | None:
        """Seconds at full speed for a step or a device call on `cobot` starting `at`; None
        for a program the simulator does not have, or a step it refuses or cannot reach."""
        if "program" in command:
            # Every step comes here: one known from where its arm stands costs two look-ups.
            arm = self._arms.get(cobot, self._home)
            known = arm.steps.get(id(command)) or self._step(arm, command)
            if known is None:
                return None
            seconds, self._arms[cobot] = known
            return seconds
        method, args = command["method"], command["args"]
        if method == "Devices/LinearAxis/Move":
            return float(args[1]) / 1000
        if method == WAIT_PLACE:
            # What is left of the occupation: the cobot moved to its wait position meanwhile.
            left = max(self._clears_at.get(cobot, at) - at, 0.0)
            return min(left, float(args[0]) / 1000)
        return _DEVICE_SECONDS.get(method, 0.0)

    def answer(
        self, cobot: str, command: Mapping[str, Any], rng: random.Random, at: float
    ) -> Mapping[str, Any] | None:
        """A device call's outputs by name as it ends `at`, with the simulator's odds."""
        if command["method"] == CHECK_PLACE and at < self._clears_at.get(cobot, at):
            return {"free": False}  # still occupied: the sensor draws nothing new
        answer = _draw(command, rng)
        if answer is not None:
            self.saw(cobot, command, answer, at)
        return answer

    def saw(
        self, cobot: str, command: Mapping[str, Any], answer: Mapping[str, Any], at: float
    ) -> None:
        """Takes in a device's answer given by another (a recorded run's) as it ends `at`: an
        occupied place position makes the cobot's next wait last until it clears."""
        if command["method"] == CHECK_PLACE and answer.get("free") is False:
            self._clears_at[cobot] = at + sensors.CLEARS_AFTER_SECONDS

    def _step(self, arm: _Arm, command: Mapping[str, Any]) -> tuple[float, _Arm] | None:
        """The step's seconds from `arm` and where it leaves the arm, kept on the arm; None
        for a program the simulator does not have, or a step it refuses or cannot reach."""
        request = self._request(command)
        if request is None:
            return None
        known = self._plan(arm, request)
        if known is not None:
            arm.steps[id(command)] = known
        return known

    def _plan(self, arm: _Arm, request: _Request) -> tuple[float, _Arm] | None:
        """The step's seconds from `arm` and where it leaves the arm (one `_Arm` per state,
        whichever cobot reached it); None when the program refuses it or cannot reach."""
        program, number, workspace, poses = request
        variables = arm.variables if arm.program == program.name else program.initial_variables()
        key = (program.name, arm.joints, tuple(sorted(variables.items())), number, workspace, poses)
        known = self._steps.get(key)
        if known is None:
            try:
                plan = program.plan(
                    StepRequest((0, 0), number, workspace, poses), arm.joints, variables
                )
            except (Refused, Unreachable):
                return None
            seconds, at = 0.0, arm.joints
            for action in plan.actions:
                if isinstance(action, Move):
                    profile = move_profile(
                        at, action.target, program.tcp, action.linear, action.speed,
                        action.acceleration,
                    )  # fmt: skip
                    seconds += profile.duration
                    at = action.target
                elif isinstance(action, Dwell):
                    seconds += action.seconds
            after = _Arm(program.name, at, dict(plan.variables))
            known = self._steps[key] = (seconds, after)
        return known

    def _request(self, command: Mapping[str, Any]) -> _Request | None:
        """The step's program, number, workspace and poses; None for a program it lacks."""
        known = self._requests.get(id(command))
        if known is not None and known[0] is command:
            return known[1]
        program = PROGRAMS.get(command["program"])
        request = None
        if program is not None:
            poses = tuple(float(v) for v in command["poses"])
            request = (program, int(command["number"]), int(command["workspace"]), poses)
        self._requests[id(command)] = (command, request)
        return request


def _draw(command: Mapping[str, Any], rng: random.Random) -> Mapping[str, Any] | None:
    """A device call's outputs drawn with the simulator's odds (devices.py, sensors.py); None
    for a call that answers nothing the cases read."""
    method, args = command["method"], command["args"]
    if method == "Devices/PartDetection/Scan":
        detected = rng.random() < devices.DETECTION_PROBABILITY
        return {"detected": detected, "pose": PART_POSE if detected else [0.0] * 6}
    if method == "Devices/Inspection/Inspect":
        draw = rng.random()
        if draw < devices.DEFECT_PROBABILITY:
            return {"result": "defect"}
        unsure = draw < devices.DEFECT_PROBABILITY + devices.UNSURE_PROBABILITY
        return {"result": "unsure" if unsure else "ok"}
    if method == "Devices/Recognition/Gesture":
        return {"detected": rng.random() < sensors.GESTURE_PROBABILITY.get(args[0], 0.0)}
    if method == "Devices/Recognition/Face":
        return {"authorized": rng.random() < sensors.FACE_PROBABILITY}
    if method == "Devices/Recognition/Screws":
        expected = int(args[0])
        missing = rng.random() < sensors.SCREWS_MISSING_PROBABILITY
        return {"found": rng.randrange(expected) if missing and expected > 0 else expected}
    if method == CHECK_PLACE:
        return {"free": rng.random() >= sensors.OCCUPIED_PROBABILITY}
    if method == WAIT_PLACE:
        return {"free": True}  # it clears before any timeout the use cases give
    return None


_DEVICE_SECONDS: Final = {
    "Devices/PartDetection/Scan": devices.SCAN_SECONDS,
    "Devices/Inspection/Inspect": devices.INSPECT_SECONDS,
    "Devices/Display/Show": 0.0,
    "Devices/Recognition/Gesture": sensors.RECOGNITION_SECONDS,
    "Devices/Recognition/Face": sensors.RECOGNITION_SECONDS,
    "Devices/Recognition/Screws": sensors.RECOGNITION_SECONDS,
    CHECK_PLACE: 0.0,
}
