"""The cell's devices under Devices/: linear axis, part detection, inspection, display."""

import asyncio

import pytest

from hrc_gateway.backend import CommandFailed
from tests.gateway.sim.cell import Cell


async def test_the_linear_axis_is_moving_until_the_move_is_done(cell: Cell) -> None:
    assert cell.value("Devices/LinearAxis/Position") == "left"
    move = asyncio.create_task(cell.space.call("Devices/LinearAxis/Move", "right", 4000))
    await cell.recorder.wait_for("Devices/LinearAxis/Position", "moving")
    assert not move.done()
    assert await move == []
    assert cell.value("Devices/LinearAxis/Position") == "right"


async def test_the_linear_axis_refuses_bad_arguments_and_a_second_move(cell: Cell) -> None:
    for direction, duration in (("up", 100), ("left", -1), ("left", 10**9)):
        with pytest.raises(CommandFailed) as refused:
            await cell.space.call("Devices/LinearAxis/Move", direction, duration)
        assert refused.value.status == "BadInvalidArgument"
        assert ("direction" if direction == "up" else "duration_ms") in str(refused.value)
    first = asyncio.create_task(cell.space.call("Devices/LinearAxis/Move", "right", 2000))
    await cell.recorder.wait_for("Devices/LinearAxis/Position", "moving")
    with pytest.raises(CommandFailed, match="already moving"):
        await cell.space.call("Devices/LinearAxis/Move", "left", 100)
    await first


async def test_a_scan_and_an_inspection_take_two_seconds(cell: Cell) -> None:
    loop = asyncio.get_running_loop()
    for method, arguments in (("PartDetection/Scan", ()), ("Inspection/Inspect", (1,))):
        started = loop.time()
        await cell.space.call(f"Devices/{method}", *arguments)
        assert loop.time() - started >= 2.0 * 0.02 * 0.95


async def test_part_detection_finds_parts_in_the_box_two_times_in_three() -> None:
    cell = await Cell.start(time_scale=0, seed=5)
    try:
        results = [await cell.space.call("Devices/PartDetection/Scan") for _ in range(30)]
    finally:
        await cell.close()
    found = [pose for detected, pose in results if detected]
    assert 10 < len(found) < 30  # two in three, seeded
    for pose in found:
        assert isinstance(pose, list)
        x, y, z, rx, ry, rz = (float(v) for v in pose)
        assert 0 <= x <= 0.4
        assert 0 <= y <= 0.5
        assert 0 <= z <= 0.1
        assert (rx, ry, rz) == (0.0, 0.0, 0.0)
    missed = [pose for detected, pose in results if not detected]
    assert all(pose == [0.0] * 6 for pose in missed)


async def test_the_next_scan_result_can_be_fixed_once(cell: Cell) -> None:
    assert "Devices/PartDetection/NextResult" in cell.space.writable
    await cell.backend.write_variable("Devices/PartDetection/NextResult", "none")
    assert await cell.space.call("Devices/PartDetection/Scan") == [False, [0.0] * 6]
    await cell.backend.write_variable("Devices/PartDetection/NextResult", "0.1 0.2 0.03 0 0 0.5")
    assert await cell.space.call("Devices/PartDetection/Scan") == [
        True,
        [0.1, 0.2, 0.03, 0.0, 0.0, 0.5],
    ]
    assert cell.value("Devices/PartDetection/NextResult") == ""
    with pytest.raises(CommandFailed, match="six numbers") as refused:
        await cell.backend.write_variable("Devices/PartDetection/NextResult", "0.1 0.2")
    assert refused.value.status == "BadInvalidArgument"


async def test_inspection_says_ok_defect_or_unsure_and_can_be_fixed() -> None:
    cell = await Cell.start(time_scale=0)
    try:
        results = {(await cell.space.call("Devices/Inspection/Inspect", 3))[0] for _ in range(30)}
        assert results == {"ok", "defect", "unsure"}
        await cell.backend.write_variable("Devices/Inspection/NextResult", "unsure")
        assert await cell.space.call("Devices/Inspection/Inspect", 2) == ["unsure"]
        await cell.backend.write_variable("Devices/Inspection/NextResult", "defect")
        assert await cell.space.call("Devices/Inspection/Inspect", 1) == ["defect"]
        with pytest.raises(CommandFailed) as refused:
            await cell.backend.write_variable("Devices/Inspection/NextResult", "NOK")
        assert refused.value.status == "BadInvalidArgument"
        with pytest.raises(CommandFailed, match="spot") as refused:
            await cell.space.call("Devices/Inspection/Inspect", -1)
        assert refused.value.status == "BadInvalidArgument"
    finally:
        await cell.close()


async def test_the_display_shows_the_last_text(cell: Cell) -> None:
    await cell.space.call("Devices/Display/Show", "Wave hand to start")
    assert cell.value("Devices/Display/Text") == "Wave hand to start"


async def test_the_same_seed_gives_the_same_parts() -> None:
    cells = [await Cell.start(seed=42, time_scale=0), await Cell.start(seed=42, time_scale=0)]
    try:
        scans = [
            [await c.space.call("Devices/PartDetection/Scan") for _ in range(5)] for c in cells
        ]
        assert scans[0] == scans[1]
    finally:
        for c in cells:
            await c.close()


async def test_other_variables_are_not_writable(cell: Cell) -> None:
    with pytest.raises(CommandFailed) as refused:
        await cell.backend.write_variable("Devices/Display/Text", "hello")
    assert refused.value.status == "BadNotWritable"
