"""The step faults a test or a demo injects through Simulator/InjectFault.

Only the faults that live in the program's steps are kept here (a hang, a
slowdown); a protective stop is the robot's (robot.py), a disconnect the
gateway's. None of them survives a gateway restart except the protective
stop, which the robot itself keeps.
"""

from __future__ import annotations

import asyncio
import math
from collections.abc import Awaitable, Callable
from typing import Final

from hrc_gateway.backend import CommandFailed

PROTECTIVE_STOP: Final = "protective-stop"
DISCONNECT: Final = "disconnect"
HANG_NEXT_STEP: Final = "hang-next-step"
SLOW_STEPS: Final = "slow-steps"
KINDS: Final = (PROTECTIVE_STOP, DISCONNECT, HANG_NEXT_STEP, SLOW_STEPS)

MAX_SLOWDOWN: Final = 1000.0


def check_kind(kind: str) -> None:
    """CommandFailed("BadInvalidArgument") unless `kind` is a fault the simulator knows."""
    if kind not in KINDS:
        raise CommandFailed(
            f"kind must be one of {', '.join(KINDS)}, not {kind!r}.", "BadInvalidArgument"
        )


def parse_slowdown(argument: str) -> float:
    """The factor of a slow-steps fault; CommandFailed("BadInvalidArgument") if it is none."""
    try:
        factor = float(argument)
    except ValueError:
        factor = math.nan
    if not 1 <= factor <= MAX_SLOWDOWN:
        raise CommandFailed(
            f"argument must be the slow-steps factor, a number from 1 to {MAX_SLOWDOWN:.0f}, "
            f"not {argument!r}.",
            "BadInvalidArgument",
        )
    return factor


class Faults:
    """The hang and slowdown in effect; `on_change` publishes Simulator/Fault."""

    def __init__(self, on_change: Callable[[], Awaitable[None]]) -> None:
        self.slowdown = 1.0
        self.hang_armed = False
        self.hanging = False
        self._cleared = asyncio.Event()
        self._on_change = on_change

    async def arm_hang(self) -> None:
        self.hang_armed = True
        self._cleared.clear()
        await self._on_change()

    async def slow_steps(self, factor: float) -> None:
        self.slowdown = factor
        await self._on_change()

    async def clear(self) -> None:
        """Ends the hang (the hung step finishes) and the slowdown."""
        self.hang_armed = False
        self.slowdown = 1.0
        self._cleared.set()
        await self._on_change()

    async def hang_if_armed(self) -> None:
        """Called when a step's actions are done: blocks until ClearFault if a hang is armed."""
        if not self.hang_armed:
            return
        self.hang_armed = False
        self.hanging = True
        await self._on_change()
        try:
            await self._cleared.wait()
        finally:
            self.hanging = False
        await self._on_change()

    def describe(self, *, protective_stop: bool) -> str:
        """Simulator/Fault: the faults in effect, "" when none."""
        faults = []
        if protective_stop:
            faults.append(PROTECTIVE_STOP)
        if self.hang_armed or self.hanging:
            faults.append(HANG_NEXT_STEP)
        if self.slowdown != 1.0:
            faults.append(f"{SLOW_STEPS} {self.slowdown:g}")
        return ", ".join(faults)
