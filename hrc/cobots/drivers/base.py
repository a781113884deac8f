"""The contract of a cobot driver: commands, one step at a time, typed errors.

Every error says whether retrying can help (`transient`): a dead gateway or a
timeout may pass; a wrong register, a refused command or a protective stop
needs a person. A step that failed after it was sent is *in doubt*; the
runtime asks the driver again with the same fencing token, and the driver
checks the cobot's registers before it sends anything.
"""

from __future__ import annotations

import abc
import dataclasses
from collections.abc import Callable, Mapping, Sequence
from typing import Any

from hrc_gateway import urua


class DriverError(Exception):
    """A cobot command that did not succeed; `transient` says whether a retry may help."""

    transient = False

    def __init__(self, message: str, *, state: Mapping[str, Any] | None = None) -> None:
        super().__init__(message)
        # The cobot's state when it failed, for the incident (may be empty).
        self.state: dict[str, Any] = dict(state or {})


class CobotUnreachable(DriverError):
    """The gateway did not answer (down, network, security handshake); retry later."""

    transient = True


def unreachable_message(cobot: str) -> str:
    """What a person reads whenever a session to the cobot cannot be opened.

    The same words whatever is (or is not) listening at the endpoint, refused,
    silent, not OPC UA, or refusing the secure channel: anything more would let
    an engineer who registers an endpoint scan ports with it. The detail goes to
    the server's log.
    """
    return f"Cannot reach cobot {cobot} at its endpoint."


class StepTimeout(DriverError):
    """The cobot did not acknowledge in time; the step is in doubt, so retry with the same token."""

    transient = True


class CobotBusy(DriverError):
    """The cobot is still running another step's handshake; retry when it is done."""

    transient = True


class CommandRefused(DriverError):
    """The gateway refused the command (bad status); its message says why."""


class DriverNotSetUp(DriverError):
    """This installation's own certificate, key or pinned gateway certificate is missing:
    nothing was sent, and a person must make them (`manage.py cobot_certificates`)."""


class InvalidCommand(DriverError):
    """The command names something that does not exist or has the wrong type or range."""


class CobotStopped(DriverError):
    """The cobot is in a protective or emergency stop; a person must clear it at the cell.

    The software never clears such a stop itself.
    """


class CobotNotReady(DriverError):
    """The cobot is not powered, not running its program, or in a mode where it cannot move."""


class CobotPaused(CobotNotReady):
    """The cobot's program is paused (for an operator in a shared area, a cell's STOP, or at the
    pendant) before the step was sent: the step waits in its queue for the resume, retries spared.
    """


class CobotStarting(CobotNotReady):
    """The cobot is booting or powering on: it gets to Idle or Running by itself, so retry."""

    transient = True


@dataclasses.dataclass(frozen=True)
class Fence:
    """The fencing token of a step: which step (id) and which try (attempt).

    The cobot echoes it when it acknowledges, so a step that already ran is
    recognised and never sent again. (0, 0) means no token.
    """

    step_id: int
    attempt: int = 1

    def __post_init__(self) -> None:
        for name in ("step_id", "attempt"):
            value = getattr(self, name)
            if not 0 <= value <= urua.INT32_MAX:
                raise ValueError(
                    f"The fence's {name} must be within 0..{urua.INT32_MAX}, not {value}"
                )

    def __str__(self) -> str:
        return f"{self.step_id}.{self.attempt}"


NO_FENCE = Fence(0, 0)


@dataclasses.dataclass(frozen=True)
class StepCommand:
    """One step for the cobot's program: step number, workspace, up to two poses, and its token."""

    step: int
    fence: Fence
    workspace: int = 0
    # Up to two poses (x, y, z, rx, ry, rz), flattened; missing values are 0.
    poses: Sequence[float] = ()

    def __post_init__(self) -> None:
        if len(self.poses) > len(urua.POSE_REGISTERS):
            raise ValueError(f"A step carries at most two poses (12 values), got {len(self.poses)}")
        for name in ("step", "workspace"):
            urua.coerce_register_value("Int0", getattr(self, name))
        for value in self.poses:
            urua.coerce_register_value("Double0", value)


@dataclasses.dataclass(frozen=True)
class StepResult:
    """What came of a step: the program's outcome and whether this call sent it."""

    fence: Fence
    # urua.OUTCOMES' name of output Int28: "ran", "duplicate", "unknown step", ...
    outcome: str
    # False when the cobot had already run this token and nothing was sent.
    sent: bool
    seconds: float


class CobotDriver(abc.ABC):
    """A connection to one cobot. Implementations keep one long-lived session."""

    name: str

    @abc.abstractmethod
    async def close(self) -> None: ...

    @abc.abstractmethod
    async def run_step(
        self,
        command: StepCommand,
        *,
        timeout: float | None = None,
        on_sent: Callable[[], None] | None = None,
    ) -> StepResult:
        """Runs one step exactly once, or raises a DriverError.

        Calling it again with the same fence after a crash finishes the
        handshake of the step in flight instead of sending it again.
        `on_sent` is called (on the driver's thread) as soon as the cobot has
        accepted the step, long before it has run; not when nothing was sent.
        """

    @abc.abstractmethod
    async def state(self, *, fresh: bool = True) -> dict[str, Any]:
        """The cobot's state: robot mode, safety mode, program state, program, last error.

        `fresh=False` may answer from what the driver already knows (a
        subscription), when nothing it did since can have changed it.
        """

    @abc.abstractmethod
    async def call(self, method: str, *arguments: Any, timeout: float | None = None) -> list[Any]:
        """Calls a URUA method (PowerOn, SelectProgram, StartProgram, ...) by its path; returns its outputs."""
