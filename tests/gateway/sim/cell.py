"""A simulated cell for the tests: SimBackend behind a fake gateway.

FakeSpace stands for the OPC UA server's GatewaySpace (the server is tested
on its own), Recorder for its `publish`: it keeps every published change in
order, so a test can ask what was published and when.
"""

from __future__ import annotations

import asyncio
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from hrc_gateway import urua
from hrc_gateway.backend import MethodHandler, RegisterValue, Value
from hrc_gateway.sim import SimBackend

ZERO_POSE = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
TIMEOUT = 5.0


class FakeSpace:
    """The nodes a backend added, and the methods to call as a client would."""

    def __init__(self) -> None:
        self.variables: dict[str, Value] = {}
        self.writable: set[str] = set()
        # The element type a variable was declared with, when not left to its value.
        self.types: dict[str, str] = {}
        self.methods: dict[str, tuple[MethodHandler, Sequence[tuple[str, str]]]] = {}
        self.outputs: dict[str, Sequence[tuple[str, str]]] = {}
        self.dropped = 0

    async def add_variable(
        self, path: str, value: Value, *, writable: bool = False, vtype: str | None = None
    ) -> None:
        assert path not in self.variables, f"{path} added twice"
        self.variables[path] = value
        if writable:
            self.writable.add(path)
        if vtype is not None:
            self.types[path] = vtype

    async def add_method(
        self,
        path: str,
        handler: MethodHandler,
        inputs: Sequence[tuple[str, str]] = (),
        outputs: Sequence[tuple[str, str]] = (),
    ) -> None:
        assert path not in self.methods, f"{path} added twice"
        self.methods[path] = (handler, inputs)
        self.outputs[path] = outputs

    async def drop_connections(self) -> None:
        self.dropped += 1

    async def call(self, path: str, *arguments: Any) -> list[Value]:
        handler, inputs = self.methods[path]
        assert len(arguments) == len(inputs), f"{path} takes {inputs}"
        return list(await handler(*arguments))


class Recorder:
    """A `publish` that remembers every change, in order, with the loop time it came."""

    def __init__(self) -> None:
        self.values: dict[str, Value] = {}
        self.history: list[tuple[float, dict[str, Value]]] = []
        self.repeated: list[str] = []  # paths published again with the value they had
        self._changed = asyncio.Condition()

    async def __call__(self, changes: Mapping[str, Value]) -> None:
        for path, value in changes.items():
            if path in self.values and self.values[path] == value:
                self.repeated.append(path)
        self.values.update(changes)
        self.history.append((asyncio.get_running_loop().time(), dict(changes)))
        async with self._changed:
            self._changed.notify_all()

    def series(self, path: str) -> list[Value]:
        """Every value published at `path`, in order."""
        return [changes[path] for _, changes in self.history if path in changes]

    def mark(self) -> int:
        """A point in the history; `since(mark)` gives what came after it."""
        return len(self.history)

    def since(self, mark: int, path: str) -> list[Value]:
        return [changes[path] for _, changes in self.history[mark:] if path in changes]

    async def wait_for(
        self, path: str, expected: Value | Callable[[Value], bool], timeout: float = TIMEOUT
    ) -> Value:
        """The value at `path` once it equals `expected` (or satisfies it, if callable)."""

        def met() -> bool:
            if path not in self.values:
                return False
            value = self.values[path]
            return bool(expected(value)) if callable(expected) else value == expected

        async with asyncio.timeout(timeout), self._changed:
            await self._changed.wait_for(met)
        return self.values[path]


@dataclass(frozen=True)
class Ack:
    """What the program wrote back for a step."""

    token: tuple[int, int]
    step: int
    outcome: int


def out(name: str) -> str:
    return urua.register_path("Outputs", name)


def step_inputs(
    step: int,
    workspace: int = 0,
    token: tuple[int, int] = (0, 0),
    pose: Sequence[float] = ZERO_POSE,
    second_pose: Sequence[float] = ZERO_POSE,
) -> dict[str, RegisterValue]:
    """One write request as a client sends a step: data, token, then Bit64."""
    values: dict[str, RegisterValue] = {
        urua.STEP: step,
        urua.WORKSPACE: workspace,
        urua.FENCE_STEP: token[0],
        urua.FENCE_ATTEMPT: token[1],
    }
    for name, value in zip(urua.POSE_REGISTERS, (*pose, *second_pose), strict=True):
        values[name] = float(value)
    values[urua.HANDSHAKE_BIT] = True
    return values


class Cell:
    """A started SimBackend with its fake gateway."""

    def __init__(self, backend: SimBackend, space: FakeSpace, recorder: Recorder) -> None:
        self.backend = backend
        self.space = space
        self.recorder = recorder

    @classmethod
    async def start(
        cls,
        *,
        time_scale: float = 0.02,
        state_file: Path | None = None,
        seed: int | None = 7,
        name: str = "cobot1",
    ) -> Cell:
        backend = SimBackend(name, time_scale=time_scale, state_file=state_file, seed=seed)
        cell = cls(backend, FakeSpace(), Recorder())
        await backend.start(cell.space, cell.recorder)
        return cell

    def value(self, path: str) -> Value:
        return self.recorder.values[path]

    @property
    def joints(self) -> list[float]:
        return list(self.value("Axes/ActualPositions/AxisPositions"))  # type: ignore[arg-type]

    async def ready(self, program: str) -> None:
        """Powered on, `program` loaded and playing."""
        await self.backend.power_on()
        await self.backend.load_program(program)
        await self.backend.play()

    async def send(self, step: int, **kwargs: Any) -> None:
        await self.backend.write_inputs(step_inputs(step, **kwargs))

    async def acknowledged(self, timeout: float = TIMEOUT) -> Ack:
        await self.recorder.wait_for(out(urua.HANDSHAKE_BIT), True, timeout)
        outputs = self.backend.registers.outputs
        return Ack(
            (int(outputs[urua.FENCE_STEP]), int(outputs[urua.FENCE_ATTEMPT])),
            int(outputs[urua.STEP]),
            int(outputs[urua.OUTCOME]),
        )

    async def release(self) -> None:
        await self.backend.write_inputs({urua.HANDSHAKE_BIT: False})
        await self.recorder.wait_for(out(urua.HANDSHAKE_BIT), False)

    async def step(self, step: int, **kwargs: Any) -> Ack:
        """The client side of one full handshake."""
        await self.send(step, **kwargs)
        ack = await self.acknowledged()
        await self.release()
        return ack

    async def moving(self) -> None:
        """Returns once the arm is moving."""
        await self.recorder.wait_for("Axes/ActualVelocities/AxisVelocities", is_moving)

    async def close(self) -> None:
        await self.backend.close()


def is_moving(velocities: Value) -> bool:
    """True for joint velocities of an arm in motion."""
    return isinstance(velocities, list) and any(abs(float(v)) > 1e-6 for v in velocities)
