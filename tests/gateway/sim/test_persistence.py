"""The controller outlives the gateway: state saved to a file and read back on start."""

import asyncio
import json
import logging
from pathlib import Path

import pytest

from hrc_gateway import urua
from hrc_gateway.sim import SimBackend
from hrc_gateway.sim.fencing import ExecutionLog, StepRequest
from hrc_gateway.sim.kinematics import HOME
from tests.gateway.sim.cell import Cell, out

FIXTURE = "Collaboration_Fixture"


async def test_a_restarted_gateway_finishes_the_interrupted_step_without_counting_it_again(
    tmp_path: Path,
) -> None:
    state = tmp_path / "cobot1.json"
    first = await Cell.start(state_file=state)
    await first.ready(FIXTURE)
    await first.send(2, token=(21, 1))  # five actions: approach, down, grip, up, home
    await first.moving()
    assert first.value("Simulator/Executions") == 1
    await first.close()  # the gateway dies mid-step; the robot keeps its state

    second = await Cell.start(state_file=state)
    try:
        assert second.value(urua.STATE_ROBOT_MODE) == "Running"
        assert second.value(urua.STATE_PROGRAM_STATE) == "Playing"
        assert second.value(urua.STATE_CURRENT_PROGRAM) == f"/programs/{FIXTURE}.urp"
        assert second.value("Register/Inputs/Bitregister/Bit64") is True
        ack = await second.acknowledged()
        assert (ack.token, ack.outcome) == ((21, 1), urua.OUTCOME_RAN)
        assert second.joints == pytest.approx(list(HOME))  # step 2 ends at home
        assert second.value("Simulator/Executions") == 1
        assert second.value("Simulator/ExecutedSteps") == [f"21.1 step=2 program={FIXTURE}"]
        await second.release()
        assert (await second.step(2, token=(21, 1))).outcome == urua.OUTCOME_DUPLICATE
    finally:
        await second.close()


async def test_a_restart_after_the_acknowledgement_waits_for_the_client_to_let_go(
    tmp_path: Path,
) -> None:
    state = tmp_path / "cobot1.json"
    first = await Cell.start(state_file=state)
    await first.ready(FIXTURE)
    await first.send(1, token=(22, 1))
    await first.acknowledged()
    await first.close()

    second = await Cell.start(state_file=state)
    try:
        assert second.value(out("Bit64")) is True
        assert second.value(out(urua.OUTCOME)) == urua.OUTCOME_RAN
        await second.release()
        assert second.value("Simulator/Executions") == 1
    finally:
        await second.close()


async def test_registers_power_program_speed_and_devices_are_kept(tmp_path: Path) -> None:
    state = tmp_path / "cobot1.json"
    first = await Cell.start(state_file=state)
    await first.ready(FIXTURE)
    await first.backend.pause()
    await first.backend.set_speed_override(30)
    await first.backend.write_inputs({"Int40": 12, "Double40": 0.5})
    await first.space.call("Devices/Display/Show", "Mount the part")
    await first.space.call("Devices/LinearAxis/Move", "right", 100)
    await first.close()

    second = await Cell.start(state_file=state)
    try:
        assert second.value(urua.STATE_PROGRAM_STATE) == "Paused"
        assert second.value("State/Override") == 30.0
        assert second.value("Register/Inputs/Intregister/Int40") == 12
        assert second.value("Register/Inputs/Doubleregister/Double40") == 0.5
        assert second.value("Devices/Display/Text") == "Mount the part"
        assert second.value("Devices/LinearAxis/Position") == "right"
        await second.backend.play()
        assert (await second.step(1, token=(23, 1))).outcome == urua.OUTCOME_RAN
    finally:
        await second.close()


async def test_the_file_is_replaced_whole_and_holds_the_execution_record(tmp_path: Path) -> None:
    state = tmp_path / "cobot1.json"
    cell = await Cell.start(state_file=state)
    try:
        await cell.ready(FIXTURE)
        await cell.step(3, workspace=1, token=(24, 3))
        saved = json.loads(state.read_text())
        assert saved["format"] == 1
        assert saved["log"]["executions"] == 1
        # The step ids seen go to an append-only journal, not the snapshot.
        journal = state.with_name("cobot1.json.journal").read_text().splitlines()
        assert "24 3 1" in journal
        # The release is saved with the next coalesced save (the client's bit write).
        for _ in range(100):
            if json.loads(state.read_text())["runner"]["phase"] == "waiting":
                break
            await asyncio.sleep(0.01)
        assert json.loads(state.read_text())["runner"]["phase"] == "waiting"
        # No temporary left behind; the step log beside them (test_step_log.py).
        assert sorted(p.name for p in tmp_path.iterdir()) == [
            "cobot1.json", "cobot1.json.journal", "cobot1.json.steps",
        ]  # fmt: skip
    finally:
        await cell.close()


@pytest.mark.parametrize(
    "content",
    [
        "{not json",
        '{"format": 1, "arm": {"robot_mode": "Flying"}}',
        '{"format": 99}',
        "[]",
        "[" * 100_000,
    ],
    ids=["garbage", "bad-arm", "other-format", "not-an-object", "nested-too-deep"],
)
async def test_an_unreadable_state_file_is_set_aside_and_the_robot_starts_fresh(
    tmp_path: Path, caplog: pytest.LogCaptureFixture, content: str
) -> None:
    state = tmp_path / "cobot1.json"
    state.write_text(content)
    with caplog.at_level(logging.WARNING):
        cell = await Cell.start(state_file=state)
    try:
        assert "starting fresh" in caplog.text
        assert cell.value(urua.STATE_ROBOT_MODE) == "Power Off"
        assert (tmp_path / "cobot1.json.corrupt").read_text() == content
        await cell.backend.power_on()
        assert json.loads(state.read_text())["arm"]["robot_mode"] == "Running"
    finally:
        await cell.close()


async def test_a_robot_saved_while_powering_on_comes_back_powered_off(tmp_path: Path) -> None:
    state = tmp_path / "cobot1.json"
    first = await Cell.start(state_file=state)
    await first.backend.load_program(FIXTURE)
    await first.close()
    saved = json.loads(state.read_text())
    saved["arm"]["robot_mode"] = "Booting"
    saved["arm"]["program_state"] = "Playing"
    state.write_text(json.dumps(saved))

    second = await Cell.start(state_file=state)
    try:
        assert second.value(urua.STATE_ROBOT_MODE) == "Power Off"
        assert second.value(urua.STATE_PROGRAM_STATE) == "Stopped"
        assert second.backend._program_task is None
    finally:
        await second.close()


async def test_closing_a_backend_that_never_started_leaves_the_saved_state_alone(
    tmp_path: Path,
) -> None:
    state = tmp_path / "cobot1.json"
    first = await Cell.start(state_file=state)
    await first.backend.power_on()
    await first.close()
    saved = state.read_text()
    # The gateway failed before starting its backend (say, its port was taken).
    await SimBackend("cobot1", state_file=state).close()
    assert state.read_text() == saved


async def test_a_torn_journal_line_is_dropped_and_the_rest_kept(tmp_path: Path) -> None:
    state = tmp_path / "cobot1.json"
    cell = await Cell.start(state_file=state)
    try:
        await cell.ready(FIXTURE)
        await cell.step(3, workspace=1, token=(30, 1))
    finally:
        await cell.close()
    journal = state.with_name("cobot1.json.journal")
    journal.write_text(journal.read_text() + "31 1")  # killed in the middle of an append
    second = await Cell.start(state_file=state)
    try:
        await second.backend.play()
        assert (await second.step(3, workspace=1, token=(30, 1))).outcome == urua.OUTCOME_DUPLICATE
        assert (await second.step(3, workspace=1, token=(31, 1))).outcome == urua.OUTCOME_RAN
    finally:
        await second.close()


def test_a_compacted_journal_rebuilds_the_same_memory() -> None:
    log = ExecutionLog()
    for token in [(1, 1), (1, 2), (2, 1)]:
        log.ran(StepRequest(token, step=3, workspace=0, poses=(0.0,) * 12), "P")
    log.saw((1, 5))
    again = ExecutionLog()
    again.restore(log.to_dict(), log.compacted_journal())
    for token in [(1, 1), (1, 2), (1, 3), (1, 5), (1, 6), (2, 1), (2, 2), (3, 1)]:
        assert again.verdict(token) == log.verdict(token), token
    assert again.executions == 3
