"""URBackend against the fake UR, seen through its Backend API and what it publishes."""

from __future__ import annotations

import asyncio
from collections.abc import AsyncIterator, Callable, Iterator, Mapping, Sequence

import pytest

from hrc_gateway.backend import MethodHandler, Value
from hrc_gateway.ur.backend import URBackend
from tests.gateway.fake_ur import HOST, FakeUR, running_fake_ur
from tests.support.polling import until_async

# Short enough for a step that never finishes to fail the test quickly, long enough for CI.
COMMAND_TIMEOUT = 3.0


class Published:
    """A Publish that records every call; `values` holds the latest value per path."""

    def __init__(self) -> None:
        self.calls: list[dict[str, Value]] = []
        self.values: dict[str, Value] = {}

    async def __call__(self, values: Mapping[str, Value]) -> None:
        self.calls.append(dict(values))
        self.values.update(values)

    def index(self, path: str, value: Value) -> int:
        """The number of the first call that published `value` at `path`."""
        return next(i for i, call in enumerate(self.calls) if call.get(path) == value)

    async def until(
        self, path: str, condition: Callable[[Value], bool], timeout: float = 5.0
    ) -> Value:
        await until_async(
            lambda: path in self.values and condition(self.values[path]),
            timeout,
            message=lambda: f"{path} is {self.values.get(path)!r} after {timeout:g} s",
        )
        return self.values[path]

    async def equals(self, path: str, value: Value, timeout: float = 5.0) -> None:
        await self.until(path, lambda v: v == value, timeout)


class Space:
    """A GatewaySpace that only remembers what the backend added."""

    def __init__(self) -> None:
        self.variables: dict[str, Value] = {}
        self.methods: list[str] = []

    async def add_variable(
        self, path: str, value: Value, *, writable: bool = False, vtype: str | None = None
    ) -> None:
        self.variables[path] = value

    async def add_method(
        self,
        path: str,
        handler: MethodHandler,
        inputs: Sequence[tuple[str, str]] = (),
        outputs: Sequence[tuple[str, str]] = (),
    ) -> None:
        self.methods.append(path)

    async def drop_connections(self) -> None:
        pass


@pytest.fixture
def fake_ur() -> Iterator[FakeUR]:
    with running_fake_ur() as fake:
        yield fake


@pytest.fixture
def published() -> Published:
    return Published()


def make_backend(fake: FakeUR, command_timeout: float = COMMAND_TIMEOUT) -> URBackend:
    return URBackend(
        "cobot1",
        robot_host=HOST,
        dashboard_port=fake.dashboard_port,
        command_timeout=command_timeout,
        programs=["hrc_steps", "/programs/pick_and_place.urp"],
    )


@pytest.fixture
async def backend(fake_ur: FakeUR, published: Published) -> AsyncIterator[URBackend]:
    """A started backend; the fake robot is powered off with no program loaded."""
    backend = make_backend(fake_ur)
    await asyncio.wait_for(backend.start(Space(), published), 15)
    yield backend
    await asyncio.wait_for(backend.close(), 10)


@pytest.fixture
async def ready(fake_ur: FakeUR, published: Published) -> AsyncIterator[URBackend]:
    """A started backend whose robot runs the HRC step program, so steps can run."""
    fake_ur.controller.make_ready()
    backend = make_backend(fake_ur)
    await asyncio.wait_for(backend.start(Space(), published), 15)
    yield backend
    await asyncio.wait_for(backend.close(), 10)
