"""What the gateway is given to serve: every value once at start, then only changes."""

import asyncio
import itertools

import pytest

from hrc_gateway import urua
from hrc_gateway.backend import Value
from tests.gateway.sim.cell import Cell

FIXTURE = "Collaboration_Fixture"


def same_type(value: Value, initial: Value) -> bool:
    """As the gateway's typed nodes take it: an int is fine for a Double, not for a String."""
    if isinstance(initial, list):
        return isinstance(value, list) and (
            not initial or all(type(v) is type(initial[0]) or isinstance(v, int) for v in value)
        )
    if isinstance(initial, float):
        return isinstance(value, int | float) and not isinstance(value, bool)
    return type(value) is type(initial)


async def test_every_register_is_published_once_at_start(cell: Cell) -> None:
    first = cell.recorder.history[0][1] | cell.recorder.history[1][1]
    for direction in ("Inputs", "Outputs"):
        for name in urua.all_register_names():
            assert urua.register_path(direction, name) in first


async def test_everything_published_is_a_node_the_gateway_serves_with_its_type(
    cell: Cell,
) -> None:
    # The gateway's own table of URUA nodes; it needs asyncua, which the sim does not.
    served = pytest.importorskip("hrc_gateway.address_space").URUA_VARIABLES
    await cell.ready(FIXTURE)
    await cell.step(2, token=(1, 1))
    await cell.space.call("Simulator/InjectFault", "hang-next-step", "")
    await cell.space.call("Devices/Display/Show", "hello")
    for _, changes in cell.recorder.history:
        for path, value in changes.items():
            initial = served.get(path, cell.space.variables.get(path))
            assert initial is not None, f"{path} is not served"
            assert same_type(value, initial), f"{path}: {value!r} is not like {initial!r}"
            if cell.space.types.get(path) == "String":
                assert all(isinstance(v, str) for v in value), f"{path}: {value!r}"  # type: ignore[union-attr]
    assert cell.space.types["Simulator/ExecutedSteps"] == "String"  # a String array node


async def test_values_are_published_only_when_they_change(cell: Cell) -> None:
    await cell.ready(FIXTURE)
    await cell.step(2, token=(2, 1))
    await cell.step(3, workspace=1)
    await cell.backend.pause()
    await cell.backend.play()
    assert cell.recorder.repeated == []


async def test_motion_is_published_at_most_every_ten_milliseconds() -> None:
    # At a tenth of real time, 25 Hz of robot time would be a sample every 4 ms.
    cell = await Cell.start(time_scale=0.1)
    try:
        await cell.ready(FIXTURE)
        await cell.step(3, workspace=1)  # one MoveJ of about 1.5 s
        times = [t for t, c in cell.recorder.history if "Axes/ActualPositions/Axis1" in c]
        gaps = [b - a for a, b in itertools.pairwise(times)]
        assert len(times) > 10
        assert min(gaps) >= 0.009
    finally:
        await cell.close()


async def test_at_time_scale_zero_a_step_takes_only_its_computation() -> None:
    cell = await Cell.start(time_scale=0)
    try:
        await cell.ready("Collaboration_CollaborativeAssembly")
        loop = asyncio.get_running_loop()
        started = loop.time()
        ack = await cell.step(6, token=(3, 1))  # nine actions, four tool waits
        assert loop.time() - started < 0.05
        assert ack.outcome == urua.OUTCOME_RAN
    finally:
        await cell.close()
