"""The cell's other devices the use cases need, simulated beside the cobot (under Devices/).

They replace the prototype client service's simulations (§2.2: /linaxis,
/partdetectionsystem, /inspectionsystem, /notification), which popped up
terminals on the service host. Each takes the time the prototype's did
(scaled), and each random result can be fixed for the next call through a
writable NextResult, so a test or a demo decides what the device sees. The
use cases' other sensors (recognition, the place position) are in
sensors.py and come along with these.
"""

from __future__ import annotations

import asyncio
import math
import random
from collections.abc import Awaitable, Callable, Mapping
from typing import Any, Final

from hrc_gateway.backend import CommandFailed, GatewaySpace, Value
from hrc_gateway.sim.clock import Clock
from hrc_gateway.sim.publisher import Publisher
from hrc_gateway.sim.sensors import Sensors

AXIS_POSITION: Final = "Devices/LinearAxis/Position"
PART_NEXT: Final = "Devices/PartDetection/NextResult"
INSPECTION_NEXT: Final = "Devices/Inspection/NextResult"
DISPLAY_TEXT: Final = "Devices/Display/Text"

SCAN_SECONDS: Final = 2.0
INSPECT_SECONDS: Final = 2.0
MAX_AXIS_MOVE_MS: Final = 600_000  # ten minutes: anything longer is a typo
# As the prototype's part detection: parts found two times out of three,
# somewhere in the part box (m).
DETECTION_PROBABILITY: Final = 2 / 3
PART_BOX: Final = ((0.0, 0.4), (0.0, 0.5), (0.0, 0.1))
# The prototype drew OK / NOK / RECHECK evenly: a defect is one of three, and
# one in three the camera cannot decide ("unsure": a person looks again).
DEFECT_PROBABILITY: Final = 1 / 3
UNSURE_PROBABILITY: Final = 1 / 3
INSPECTION_RESULTS: Final = ("ok", "defect", "unsure")

_BAD_ARGUMENT: Final = "BadInvalidArgument"


class Devices:
    """Linear axis, part detection, inspection system, display and the sensors (sensors.py);
    `persist` saves their state."""

    def __init__(
        self,
        clock: Clock,
        publish: Publisher,
        rng: random.Random,
        persist: Callable[[], Awaitable[None]],
    ) -> None:
        self._clock = clock
        self._publish = publish
        self._rng = rng
        self._persist = persist
        self.axis_position = "left"
        self.part_next = ""
        self.inspection_next = ""
        self.display_text = ""
        self._axis_lock = asyncio.Lock()
        self.sensors = Sensors(clock, publish, rng, persist)

    async def add_nodes(self, space: GatewaySpace) -> None:
        await space.add_method(
            "Devices/LinearAxis/Move",
            self.move_axis,
            [("direction", "String"), ("duration_ms", "Int32")],
        )
        await space.add_method(
            "Devices/PartDetection/Scan",
            self.scan,
            (),
            [("Detected", "Boolean"), ("Pose", "Double[]")],
        )
        await space.add_method(
            "Devices/Inspection/Inspect", self.inspect, [("spot", "Int32")], [("Result", "String")]
        )
        await space.add_method("Devices/Display/Show", self.show, [("text", "String")])
        await self.sensors.add_nodes(space)
        writable = (PART_NEXT, INSPECTION_NEXT, *self.sensors.writable)
        for path, value in self.published_values().items():
            await space.add_variable(path, value, writable=path in writable)

    def published_values(self) -> dict[str, Value]:
        return {
            AXIS_POSITION: self.axis_position,
            PART_NEXT: self.part_next,
            INSPECTION_NEXT: self.inspection_next,
            DISPLAY_TEXT: self.display_text,
            **self.sensors.published_values(),
        }

    async def move_axis(self, direction: str, duration_ms: int) -> list[Value]:
        """Moves the linear axis to the `direction` end; returns when it is there."""
        if direction not in ("left", "right"):
            raise CommandFailed(
                f"direction must be 'left' or 'right', not {direction!r}.", _BAD_ARGUMENT
            )
        if not 0 <= duration_ms <= MAX_AXIS_MOVE_MS:
            raise CommandFailed(
                f"duration_ms must be 0–{MAX_AXIS_MOVE_MS}, not {duration_ms}.", _BAD_ARGUMENT
            )
        if self._axis_lock.locked():
            raise CommandFailed("The linear axis is already moving; wait until it stops.")
        async with self._axis_lock:
            await self._publish({AXIS_POSITION: "moving"})
            try:
                await self._clock.sleep(duration_ms / 1000)
            except asyncio.CancelledError:
                # A move cut short leaves the axis where it was, as far as the sim knows.
                await self._publish({AXIS_POSITION: self.axis_position})
                raise
            self.axis_position = direction
            await self._publish({AXIS_POSITION: direction})
            await self._persist()
        return []

    async def scan(self) -> list[Value]:
        """Detected (Boolean) and Pose (x, y, z, rx, ry, rz) of a part in the part box."""
        await self._clock.sleep(SCAN_SECONDS)
        fixed, self.part_next = self.part_next, ""
        await self._publish({PART_NEXT: ""})
        if fixed == "none" or (not fixed and self._rng.random() >= DETECTION_PROBABILITY):
            return [False, [0.0] * 6]
        if fixed:
            return [True, _parse_pose(fixed)]
        x, y, z = (self._rng.uniform(low, high) for low, high in PART_BOX)
        return [True, [round(x, 4), round(y, 4), round(z, 4), 0.0, 0.0, 0.0]]

    async def inspect(self, spot: int) -> list[Value]:
        """Result "ok", "defect" or "unsure" (the camera cannot tell) for the inspected `spot`."""
        if spot < 0:
            raise CommandFailed(f"spot must be 0 or more, not {spot}.", _BAD_ARGUMENT)
        await self._clock.sleep(INSPECT_SECONDS)
        fixed, self.inspection_next = self.inspection_next, ""
        await self._publish({INSPECTION_NEXT: ""})
        if fixed:
            return [fixed]
        draw = self._rng.random()
        if draw < DEFECT_PROBABILITY:
            return ["defect"]
        return ["unsure" if draw < DEFECT_PROBABILITY + UNSURE_PROBABILITY else "ok"]

    async def show(self, text: str) -> list[Value]:
        """Shows `text` on the cobot's display (the prototype's "cobot head")."""
        self.display_text = text
        await self._publish({DISPLAY_TEXT: text})
        await self._persist()
        return []

    async def write_variable(self, path: str, value: Value) -> bool:
        """Takes a client's write to a NextResult; False if `path` is not the devices'."""
        if path not in (PART_NEXT, INSPECTION_NEXT):
            return await self.sensors.write_variable(path, value)
        if not isinstance(value, str):
            raise CommandFailed(f"{path} holds a String.", "BadTypeMismatch")
        text = value.strip()
        if path == PART_NEXT:
            if text not in ("", "none"):
                _parse_pose(text)  # refuses what Scan could not return
            self.part_next = text
        else:
            if text not in ("", *INSPECTION_RESULTS):
                raise CommandFailed(
                    f"{path} must be 'ok', 'defect', 'unsure' or '' (random), not {value!r}.",
                    _BAD_ARGUMENT,
                )
            self.inspection_next = text
        await self._publish({path: text})
        await self._persist()
        return True

    def to_dict(self) -> dict[str, Any]:
        return {
            "axis_position": self.axis_position,
            "part_next": self.part_next,
            "inspection_next": self.inspection_next,
            "display_text": self.display_text,
            "sensors": self.sensors.to_dict(),
        }

    def restore(self, data: Mapping[str, Any]) -> None:
        """Takes what to_dict saved; ValueError/KeyError when it is not that."""
        axis = str(data["axis_position"])
        if axis not in ("left", "right"):
            raise ValueError(f"a linear axis at {axis!r}")
        part_next, inspection_next = str(data["part_next"]), str(data["inspection_next"])
        if part_next not in ("", "none"):
            try:
                _parse_pose(part_next)
            except CommandFailed as refused:
                raise ValueError(str(refused)) from None
        if inspection_next not in ("", *INSPECTION_RESULTS):
            raise ValueError(f"an inspection result {inspection_next!r}")
        self.axis_position, self.part_next, self.inspection_next = axis, part_next, inspection_next
        self.display_text = str(data["display_text"])
        self.sensors.restore(data.get("sensors", {}))  # absent from states saved before them


def _parse_pose(text: str) -> list[float]:
    try:
        pose = [float(v) for v in text.split()]
    except ValueError:
        pose = []
    if len(pose) != 6 or not all(math.isfinite(v) for v in pose):
        raise CommandFailed(
            f"{PART_NEXT} must be 'none', '' (random) or six numbers 'x y z rx ry rz', "
            f"not {text!r}.",
            _BAD_ARGUMENT,
        )
    return pose
