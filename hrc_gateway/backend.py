"""The base class every gateway backend implements, and what the gateway offers it.

The backend is the source of truth for every value the gateway serves: the
gateway never writes a node on its own. A client's register write reaches
`write_inputs` (already checked against the register's type and range); the
backend applies it and publishes the new values, so the address space always
shows what the robot holds. Commands that fail raise `CommandFailed`; the
gateway answers the OPC UA call with its status and puts the message in
State/LastError.
"""

from __future__ import annotations

import abc
from collections.abc import Awaitable, Callable, Mapping, Sequence
from typing import ClassVar, Protocol

# A value the gateway can serve: scalars, or arrays of doubles / strings.
Value = bool | int | float | str | list[float] | list[str]
RegisterValue = bool | int | float

# Publishes changed values, keyed by path under the cobot root
# ("State/RobotMode", "Register/Outputs/Bitregister/Bit64", ...).
Publish = Callable[[Mapping[str, Value]], Awaitable[None]]

# An OPC UA method handler: takes the call's input arguments, returns its outputs.
MethodHandler = Callable[..., Awaitable[Sequence[Value]]]


class CommandFailed(Exception):
    """A command the backend could not carry out.

    `status` is the name of the OPC UA status code the call returns
    (e.g. "BadInvalidState"); the message says what is wrong and what to do.
    """

    def __init__(self, message: str, status: str = "BadInvalidState") -> None:
        super().__init__(message)
        self.status = status


class GatewaySpace(Protocol):
    """What a backend may add to the address space besides URUA's nodes."""

    async def add_variable(
        self, path: str, value: Value, *, writable: bool = False, vtype: str | None = None
    ) -> None:
        """A variable at `path` under the root; its type is that of `value` (int → Int32).

        `vtype` names the (element) type instead, e.g. "String" for a list that may be empty.

        Writes to a writable variable reach `Backend.write_variable`.
        """

    async def add_method(
        self,
        path: str,
        handler: MethodHandler,
        inputs: Sequence[tuple[str, str]] = (),
        outputs: Sequence[tuple[str, str]] = (),
    ) -> None:
        """A method at `path`; arguments are (name, VariantType name such as "String", "Int32")."""

    async def drop_connections(self) -> None:
        """Closes every client connection at once (a fault the simulator can inject)."""


class Backend(abc.ABC):
    """A robot controller as the gateway sees it. One instance per gateway process."""

    # The --backend name.
    kind: ClassVar[str]

    def __init__(self, name: str) -> None:
        self.name = name

    @abc.abstractmethod
    async def start(self, space: GatewaySpace, publish: Publish) -> None:
        """Connects to the robot, adds any extra nodes, and publishes every value once.

        Called once, after URUA's nodes exist and before clients are served.
        Raises CommandFailed when the robot cannot be reached at all.
        """

    @abc.abstractmethod
    async def close(self) -> None:
        """Stops background work and releases the robot; idempotent."""

    # Identity, read once at start.
    @abc.abstractmethod
    async def serial_number(self) -> str: ...

    @abc.abstractmethod
    async def robot_model(self) -> str: ...

    @abc.abstractmethod
    async def programs(self) -> list[str]:
        """Base names of the programs the robot can load (no directory, no .urp)."""

    # Commands (URUA's methods). Each returns once the robot has accepted the
    # command, or raises CommandFailed.
    @abc.abstractmethod
    async def power_on(self) -> None:
        """Powers the arm on, waits for Idle and releases the brakes (with a timeout)."""

    @abc.abstractmethod
    async def brake_release(self) -> None:
        """Releases the brakes of a robot powered on to Idle and waits for Running.

        Returns at once when it is Running already; raises CommandFailed in a
        safety stop or in any other mode (powered off: power it on first).
        """

    @abc.abstractmethod
    async def power_off(self) -> None: ...

    @abc.abstractmethod
    async def load_program(self, program: str) -> None:
        """Loads a program by base name (already stripped of directory and .urp)."""

    @abc.abstractmethod
    async def play(self) -> None: ...

    @abc.abstractmethod
    async def pause(self) -> None: ...

    @abc.abstractmethod
    async def stop_program(self) -> None: ...

    @abc.abstractmethod
    async def set_operational_mode(self, mode: str | None) -> None:
        """ "MANUAL", "AUTOMATIC", or None to clear the mode."""

    @abc.abstractmethod
    async def popup(self, message: str | None) -> None:
        """Shows a message on the teach pendant; None closes it."""

    @abc.abstractmethod
    async def add_to_log(self, message: str) -> None: ...

    @abc.abstractmethod
    async def write_inputs(self, values: Mapping[str, RegisterValue]) -> None:
        """Applies one client write request's input registers, in order, as one batch.

        `values` maps register names ("Int24", "Bit64") to values already
        coerced by hrc_gateway.urua.coerce_register_value. Raises CommandFailed
        ("BadNotSupported") without applying anything when the backend cannot
        carry one of them to the robot.
        """

    @abc.abstractmethod
    async def set_speed_override(self, percent: float) -> None:
        """The speed slider, 0–100; a comfort setting, never a safety function."""

    async def write_variable(self, path: str, value: Value) -> None:
        """A client wrote a writable variable the backend added; default: refuse."""
        raise CommandFailed(f"{path} is not writable.", "BadNotWritable")
