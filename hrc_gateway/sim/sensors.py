"""The sensors the use cases ask of the cell besides the prototype's devices (devices.py).

- Recognition: the collaborative assembly's camera. The prototype stood in
  for it with `/random/boolean` (hand wave, authorised face, thumbs up, at the
  process settings' 80 / 80 / 75 %) and `/random/integer` for the screws a
  plate shows; here each is a method under Devices/Recognition/.
- PlacePosition: whether pick & place may put its part down. The prototype
  decided "place position empty?" with `Math.random()` and, when it was not,
  waited for a callback 3 s later; here a check says free or occupied, and an
  occupied position clears after 3 s, which a waiting call sees.

As in devices.py, each random answer can be fixed for the next call through
a writable Next… variable ("" = random), so a test or a demo decides what
the sensor sees. These sensors only report: nothing here moves or stops the
robot, and none of them is a safety function.
"""

from __future__ import annotations

import asyncio
import random
from collections.abc import Awaitable, Callable, Mapping
from typing import Any, Final

from hrc_gateway.backend import CommandFailed, GatewaySpace, Value
from hrc_gateway.sim.clock import Clock
from hrc_gateway.sim.publisher import Publisher

GESTURE_NEXT: Final = "Devices/Recognition/NextGesture"
FACE_NEXT: Final = "Devices/Recognition/NextFace"
SCREWS_NEXT: Final = "Devices/Recognition/NextScrews"
PLACE_FREE: Final = "Devices/PlacePosition/Free"
PLACE_NEXT: Final = "Devices/PlacePosition/NextResult"

# The prototype's process settings (§3.2): a hand wave is seen 80 % of the
# time, the user recognised as authorised 80 %, a thumbs up 75 %.
GESTURE_PROBABILITY: Final = {"hand-wave": 0.8, "thumbs-up": 0.75}
FACE_PROBABILITY: Final = 0.8
RECOGNITION_SECONDS: Final = 1.0
# The prototype drew 0–11 screws and passed a plate showing 4 or more: a
# plate misses screws one time in three. Here too; a short plate shows from
# none to one fewer than it should.
SCREWS_MISSING_PROBABILITY: Final = 1 / 3
MAX_SCREWS: Final = 100
YES_NO: Final = ("yes", "no")

# "Place pos empty?" was `Math.random() >= 0.5`; the wait for it, 3000 ms.
OCCUPIED_PROBABILITY: Final = 0.5
CLEARS_AFTER_SECONDS: Final = 3.0
MAX_WAIT_MS: Final = 600_000
PLACE_RESULTS: Final = ("free", "occupied")

_BAD_ARGUMENT: Final = "BadInvalidArgument"


class Recognition:
    """Gesture, face and screw recognition; `Next…` fixes the next answer of each."""

    def __init__(self, clock: Clock, publish: Publisher, rng: random.Random) -> None:
        self._clock = clock
        self._publish = publish
        self._rng = rng
        self.next = {GESTURE_NEXT: "", FACE_NEXT: "", SCREWS_NEXT: ""}

    async def add_nodes(self, space: GatewaySpace) -> None:
        await space.add_method(
            "Devices/Recognition/Gesture",
            self.gesture,
            [("gesture", "String")],
            [("Detected", "Boolean")],
        )
        await space.add_method(
            "Devices/Recognition/Face", self.face, (), [("Authorized", "Boolean")]
        )
        await space.add_method(
            "Devices/Recognition/Screws", self.screws, [("expected", "Int32")], [("Found", "Int32")]
        )

    async def gesture(self, gesture: str) -> list[Value]:
        """Detected: whether the camera saw the operator make `gesture` (hand-wave, thumbs-up)."""
        probability = GESTURE_PROBABILITY.get(gesture)
        if probability is None:
            raise CommandFailed(
                f"gesture must be one of {', '.join(GESTURE_PROBABILITY)}, not {gesture!r}.",
                _BAD_ARGUMENT,
            )
        await self._clock.sleep(RECOGNITION_SECONDS)
        return [await self._yes(GESTURE_NEXT, probability)]

    async def face(self) -> list[Value]:
        """Authorized: whether the face in front of the camera is one allowed to work here."""
        await self._clock.sleep(RECOGNITION_SECONDS)
        return [await self._yes(FACE_NEXT, FACE_PROBABILITY)]

    async def screws(self, expected: int) -> list[Value]:
        """Found: how many of the `expected` screws of the plate in view the camera counts."""
        if not 0 < expected <= MAX_SCREWS:
            raise CommandFailed(f"expected must be 1–{MAX_SCREWS}, not {expected}.", _BAD_ARGUMENT)
        await self._clock.sleep(RECOGNITION_SECONDS)
        fixed = await self._take(SCREWS_NEXT)
        if fixed:
            return [min(int(fixed), expected)]
        if self._rng.random() < SCREWS_MISSING_PROBABILITY:
            return [self._rng.randrange(expected)]
        return [expected]

    async def _yes(self, path: str, probability: float) -> bool:
        fixed = await self._take(path)
        if fixed:
            return fixed == "yes"
        return self._rng.random() < probability

    async def _take(self, path: str) -> str:
        fixed, self.next[path] = self.next[path], ""
        if fixed:
            await self._publish({path: ""})
        return fixed

    def check(self, path: str, text: str) -> None:
        """CommandFailed unless `text` is an answer the `path` sensor could give ("" = random)."""
        if text == "":
            return
        if path == SCREWS_NEXT:
            if not (text.isascii() and text.isdigit() and int(text) <= MAX_SCREWS):
                raise CommandFailed(
                    f"{path} must be a count of screws 0–{MAX_SCREWS} or '' (random), "
                    f"not {text!r}.",
                    _BAD_ARGUMENT,
                )
        elif text not in YES_NO:
            raise CommandFailed(f"{path} must be 'yes', 'no' or '' (random), not {text!r}.", _BAD_ARGUMENT)  # fmt: skip


class PlacePosition:
    """Whether the place position is free; an occupied one clears CLEARS_AFTER_SECONDS later."""

    def __init__(self, clock: Clock, publish: Publisher, rng: random.Random) -> None:
        self._clock = clock
        self._publish = publish
        self._rng = rng
        self.next = ""
        self._clears_at: float | None = None  # wall time (clock.now) while occupied
        self._clearing: asyncio.TimerHandle | None = None

    async def add_nodes(self, space: GatewaySpace) -> None:
        await space.add_method(
            "Devices/PlacePosition/Check", self.check_free, (), [("Free", "Boolean")]
        )
        await space.add_method(
            "Devices/PlacePosition/WaitUntilFree",
            self.wait_until_free,
            [("timeout_ms", "Int32")],
            [("Free", "Boolean")],
        )

    @property
    def free(self) -> bool:
        return self._clears_at is None or self._clock.now() >= self._clears_at

    async def check_free(self) -> list[Value]:
        """Free: whether a part may be put down now."""
        if not self.free:
            return [False]
        fixed, self.next = self.next, ""
        if fixed:
            await self._publish({PLACE_NEXT: ""})
        occupied = fixed == "occupied" or (not fixed and self._rng.random() < OCCUPIED_PROBABILITY)
        if occupied:
            await self._occupy()
        return [not occupied]

    async def wait_until_free(self, timeout_ms: int) -> list[Value]:
        """Free: returns as soon as the position is free, or False after `timeout_ms` of robot time."""
        if not 0 <= timeout_ms <= MAX_WAIT_MS:
            raise CommandFailed(f"timeout_ms must be 0–{MAX_WAIT_MS}, not {timeout_ms}.", _BAD_ARGUMENT)  # fmt: skip
        if self._clears_at is not None:
            left = max(self._clears_at - self._clock.now(), 0.0)
            limit = timeout_ms / 1000 * self._clock.time_scale
            await asyncio.sleep(min(left, limit))
        return [self.free]

    async def _occupy(self) -> None:
        wall_seconds = CLEARS_AFTER_SECONDS * self._clock.time_scale
        self._clears_at = self._clock.now() + wall_seconds
        await self._publish({PLACE_FREE: False})
        if self._clearing is not None:
            self._clearing.cancel()
        self._clearing = asyncio.get_running_loop().call_later(
            wall_seconds, lambda: asyncio.ensure_future(self._cleared())
        )

    async def _cleared(self) -> None:
        self._clearing = None
        if self.free:
            self._clears_at = None
            await self._publish({PLACE_FREE: True})

    def check(self, text: str) -> None:
        if text not in ("", *PLACE_RESULTS):
            raise CommandFailed(
                f"{PLACE_NEXT} must be 'free', 'occupied' or '' (random), not {text!r}.",
                _BAD_ARGUMENT,
            )


class Sensors:
    """Recognition and the place position, as Devices adds them to the space and saves them."""

    def __init__(
        self,
        clock: Clock,
        publish: Publisher,
        rng: random.Random,
        persist: Callable[[], Awaitable[None]],
    ) -> None:
        self.recognition = Recognition(clock, publish, rng)
        self.place = PlacePosition(clock, publish, rng)
        self._publish = publish
        self._persist = persist

    async def add_nodes(self, space: GatewaySpace) -> None:
        await self.recognition.add_nodes(space)
        await self.place.add_nodes(space)

    @property
    def writable(self) -> tuple[str, ...]:
        return (*self.recognition.next, PLACE_NEXT)

    def published_values(self) -> dict[str, Value]:
        return {**self.recognition.next, PLACE_NEXT: self.place.next, PLACE_FREE: self.place.free}

    async def write_variable(self, path: str, value: Value) -> bool:
        """Takes a client's write to a Next… variable; False if `path` is not the sensors'."""
        if path not in self.writable:
            return False
        if not isinstance(value, str):
            raise CommandFailed(f"{path} holds a String.", "BadTypeMismatch")
        text = value.strip()
        if path == PLACE_NEXT:
            self.place.check(text)
            self.place.next = text
        else:
            self.recognition.check(path, text)
            self.recognition.next[path] = text
        await self._publish({path: text})
        await self._persist()
        return True

    def to_dict(self) -> dict[str, Any]:
        return {"recognition_next": dict(self.recognition.next), "place_next": self.place.next}

    def restore(self, data: Mapping[str, Any]) -> None:
        """Takes what to_dict saved (a state saved before the sensors existed has none: kept
        as is); ValueError when it is not that."""
        recognition = data.get("recognition_next", {})
        place = str(data.get("place_next", ""))
        fixed = {path: str(recognition.get(path, "")) for path in self.recognition.next}
        try:
            self.place.check(place)
            for path, text in fixed.items():
                self.recognition.check(path, text)
        except CommandFailed as refused:
            raise ValueError(str(refused)) from None
        self.recognition.next, self.place.next = fixed, place
