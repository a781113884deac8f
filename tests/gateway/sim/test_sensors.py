"""The use cases' sensors under Devices/: the recognition camera and the place position."""

import asyncio
from collections import Counter
from pathlib import Path

import pytest

from hrc_gateway.backend import CommandFailed
from hrc_gateway.sim import sensors
from tests.gateway.sim.cell import Cell

GESTURE = "Devices/Recognition/Gesture"
FACE = "Devices/Recognition/Face"
SCREWS = "Devices/Recognition/Screws"
CHECK = "Devices/PlacePosition/Check"
WAIT = "Devices/PlacePosition/WaitUntilFree"


async def _draws(
    method: str, *arguments: object, count: int = 200, seed: int = 3
) -> Counter[object]:
    cell = await Cell.start(time_scale=0, seed=seed)
    try:
        return Counter([(await cell.space.call(method, *arguments))[0] for _ in range(count)])
    finally:
        await cell.close()


async def test_gestures_and_faces_are_seen_about_as_often_as_the_prototype_said() -> None:
    for method, arguments, probability in (
        (GESTURE, ("hand-wave",), 0.8),
        (GESTURE, ("thumbs-up",), 0.75),
        (FACE, (), 0.8),
    ):
        seen = await _draws(method, *arguments)
        assert set(seen) == {True, False}
        assert abs(seen[True] / 200 - probability) < 0.1, (method, arguments, seen)


async def test_a_plate_misses_screws_about_one_time_in_three_never_more_than_it_has() -> None:
    found = await _draws(SCREWS, 4)
    assert set(found) <= {0, 1, 2, 3, 4}
    short = sum(count for screws, count in found.items() if screws != 4)
    assert 0.2 < short / 200 < 0.45
    assert len(found) > 2  # short plates show different counts


async def test_recognition_takes_a_second_of_robot_time(cell: Cell) -> None:
    loop = asyncio.get_running_loop()
    for method, arguments in ((GESTURE, ("thumbs-up",)), (FACE, ()), (SCREWS, (4,))):
        started = loop.time()
        await cell.space.call(method, *arguments)
        assert loop.time() - started >= 1.0 * 0.02 * 0.95


async def test_the_next_recognition_can_be_fixed_once_each(cell: Cell) -> None:
    for path in ("NextGesture", "NextFace", "NextScrews"):
        assert f"Devices/Recognition/{path}" in cell.space.writable
    await cell.backend.write_variable("Devices/Recognition/NextGesture", "no")
    await cell.backend.write_variable("Devices/Recognition/NextFace", "no")
    await cell.backend.write_variable("Devices/Recognition/NextScrews", "2")
    assert await cell.space.call(GESTURE, "hand-wave") == [False]
    assert await cell.space.call(FACE) == [False]
    assert await cell.space.call(SCREWS, 4) == [2]
    assert cell.value("Devices/Recognition/NextScrews") == ""
    await cell.backend.write_variable("Devices/Recognition/NextScrews", "9")
    assert await cell.space.call(SCREWS, 4) == [4]  # a camera counts no more than there are
    await cell.backend.write_variable("Devices/Recognition/NextGesture", "yes")
    assert await cell.space.call(GESTURE, "thumbs-up") == [True]


@pytest.mark.parametrize(
    ("path", "value"),
    [
        ("Devices/Recognition/NextGesture", "maybe"),
        ("Devices/Recognition/NextFace", "1"),
        ("Devices/Recognition/NextScrews", "-1"),
        ("Devices/Recognition/NextScrews", "four"),
        ("Devices/PlacePosition/NextResult", "empty"),
    ],
)
async def test_a_next_answer_the_sensor_could_not_give_is_refused(
    cell: Cell, path: str, value: str
) -> None:
    with pytest.raises(CommandFailed) as refused:
        await cell.backend.write_variable(path, value)
    assert refused.value.status == "BadInvalidArgument"
    assert path in str(refused.value)


async def test_recognition_refuses_what_it_cannot_look_for(cell: Cell) -> None:
    with pytest.raises(CommandFailed, match="hand-wave, thumbs-up") as refused:
        await cell.space.call(GESTURE, "nod")
    assert refused.value.status == "BadInvalidArgument"
    for expected in (0, sensors.MAX_SCREWS + 1):
        with pytest.raises(CommandFailed, match="expected") as refused:
            await cell.space.call(SCREWS, expected)
        assert refused.value.status == "BadInvalidArgument"


async def test_the_place_position_is_occupied_about_half_the_time() -> None:
    cell = await Cell.start(time_scale=0, seed=11)
    try:
        free = Counter([(await cell.space.call(CHECK))[0] for _ in range(100)])
    finally:
        await cell.close()
    assert 30 < free[True] < 70


async def test_an_occupied_place_position_clears_after_three_seconds(cell: Cell) -> None:
    loop = asyncio.get_running_loop()
    await cell.backend.write_variable("Devices/PlacePosition/NextResult", "occupied")
    assert await cell.space.call(CHECK) == [False]
    occupied_at = loop.time()
    assert cell.value("Devices/PlacePosition/Free") is False
    assert await cell.space.call(CHECK) == [False]  # still there: no new draw
    assert await cell.space.call(WAIT, 60_000) == [True]
    waited = loop.time() - occupied_at
    assert 3.0 * 0.02 * 0.9 <= waited < 3.0 * 0.02 * 3
    await cell.recorder.wait_for("Devices/PlacePosition/Free", True)
    await cell.backend.write_variable("Devices/PlacePosition/NextResult", "free")
    assert await cell.space.call(CHECK) == [True]
    assert await cell.space.call(WAIT, 0) == [True]  # free: no wait at all


async def test_a_wait_shorter_than_the_clearing_says_not_free(cell: Cell) -> None:
    await cell.backend.write_variable("Devices/PlacePosition/NextResult", "occupied")
    assert await cell.space.call(CHECK) == [False]
    assert await cell.space.call(WAIT, 500) == [False]  # 0.5 s of the 3 s
    with pytest.raises(CommandFailed, match="timeout_ms") as refused:
        await cell.space.call(WAIT, -1)
    assert refused.value.status == "BadInvalidArgument"
    assert await cell.space.call(WAIT, 10_000) == [True]


async def test_fixed_answers_survive_a_restart_and_old_states_load(tmp_path: Path) -> None:
    state = tmp_path / "cobot1.json"
    first = await Cell.start(state_file=state)
    await first.backend.write_variable("Devices/Recognition/NextScrews", "1")
    await first.backend.write_variable("Devices/PlacePosition/NextResult", "occupied")
    await first.close()
    second = await Cell.start(state_file=state)
    try:
        assert second.value("Devices/Recognition/NextScrews") == "1"
        assert await second.space.call(SCREWS, 4) == [1]
        assert await second.space.call(CHECK) == [False]
    finally:
        await second.close()
    # A state saved before the sensors existed: no "sensors" among the devices.
    backend = second.backend
    saved = backend._snapshot()
    del saved["devices"]["sensors"]
    backend.devices.restore(saved["devices"])
    assert backend.devices.sensors.recognition.next["Devices/Recognition/NextScrews"] == ""
