"""Power, safety, modes and program commands, as a client of the gateway sees them."""

from pathlib import Path

import pytest

from hrc_gateway import urua
from hrc_gateway.backend import CommandFailed
from hrc_gateway.sim.programs import PROGRAMS
from tests.cobots.simulator import leave_arm_in_idle
from tests.gateway.sim.cell import Cell

PICK = "Coexistence_PickAndPlace"


async def test_a_new_robot_is_powered_off_safe_stopped_and_in_remote_control(cell: Cell) -> None:
    assert cell.value(urua.STATE_ROBOT_MODE) == "Power Off"
    assert cell.value(urua.STATE_SAFETY_MODE) == "SAFETY_MODE_NORMAL"
    assert cell.value(urua.STATE_PROGRAM_STATE) == "Stopped"
    assert cell.value(urua.STATE_CURRENT_PROGRAM) == ""
    assert cell.value("State/RobotState") == "STOPPED <unnamed>"
    assert cell.value("State/Remote") is True
    assert cell.value("State/OperationalMode") == "AUTOMATIC"
    assert cell.value("SafetyBoard/RobotVoltage") == 0.0
    assert await cell.backend.robot_model() == "UR5e"
    assert await cell.backend.programs() == list(PROGRAMS)
    assert len(PROGRAMS) == 7


async def test_power_on_boots_releases_the_brakes_and_returns_when_running(cell: Cell) -> None:
    await cell.backend.power_on()
    assert cell.recorder.series(urua.STATE_ROBOT_MODE) == [
        "Power Off",
        "Power On",
        "Booting",
        "Idle",
        "Running",
    ]
    assert cell.value("State/JointMode") == "JOINT_RUNNING_MODE"
    assert cell.value("SafetyBoard/RobotVoltage") == 48.0


async def test_power_on_when_running_returns_at_once(cell: Cell) -> None:
    await cell.backend.power_on()
    mark = cell.recorder.mark()
    await cell.backend.power_on()
    assert cell.recorder.since(mark, urua.STATE_ROBOT_MODE) == []


async def idle_cell(state_file: Path) -> Cell:
    """A cell whose arm was powered on to Idle (brakes on) before the gateway started."""
    await (await Cell.start(state_file=state_file)).close()
    leave_arm_in_idle(state_file)
    return await Cell.start(state_file=state_file)


async def test_brake_release_takes_an_idle_arm_to_running(tmp_path: Path) -> None:
    cell = await idle_cell(tmp_path / "sim.json")
    try:
        assert cell.value(urua.STATE_ROBOT_MODE) == "Idle"
        await cell.backend.brake_release()
        assert cell.recorder.series(urua.STATE_ROBOT_MODE) == ["Idle", "Running"]
        assert cell.value("State/JointMode") == "JOINT_RUNNING_MODE"
    finally:
        await cell.close()


async def test_brake_release_of_a_powered_off_arm_is_refused_and_says_power_it_on(
    cell: Cell,
) -> None:
    with pytest.raises(CommandFailed, match="Power it on first") as refused:
        await cell.backend.brake_release()
    assert refused.value.status == "BadInvalidState"
    assert cell.value(urua.STATE_ROBOT_MODE) == "Power Off"


async def test_brake_release_of_a_running_arm_changes_nothing(cell: Cell) -> None:
    await cell.backend.power_on()
    mark = cell.recorder.mark()
    await cell.backend.brake_release()
    assert cell.recorder.since(mark, urua.STATE_ROBOT_MODE) == []


async def test_brake_release_in_a_protective_stop_is_refused_and_the_stop_stays(
    tmp_path: Path,
) -> None:
    cell = await idle_cell(tmp_path / "sim.json")
    try:
        await cell.space.call("Simulator/InjectFault", "protective-stop", "")
        with pytest.raises(CommandFailed, match="teach pendant"):
            await cell.backend.brake_release()
        assert cell.value(urua.STATE_ROBOT_MODE) == "Idle"
        assert cell.value(urua.STATE_SAFETY_MODE) == "SAFETY_MODE_PROTECTIVE_STOP"
    finally:
        await cell.close()


async def test_power_on_in_a_protective_stop_says_a_person_must_clear_it(cell: Cell) -> None:
    await cell.space.call("Simulator/InjectFault", "protective-stop", "")
    with pytest.raises(CommandFailed, match="teach pendant") as refused:
        await cell.backend.power_on()
    assert refused.value.status == "BadInvalidState"
    assert cell.value(urua.STATE_ROBOT_MODE) == "Power Off"


async def test_power_off_stops_the_program_and_cuts_power(cell: Cell) -> None:
    await cell.ready(PICK)
    await cell.backend.power_off()
    assert cell.value(urua.STATE_PROGRAM_STATE) == "Stopped"
    assert cell.value(urua.STATE_ROBOT_MODE) == "Power Off"
    assert cell.backend._program_task is None


async def test_loading_a_program_names_it_as_the_dashboard_does(cell: Cell) -> None:
    await cell.backend.load_program(PICK)
    assert cell.value(urua.STATE_CURRENT_PROGRAM) == f"/programs/{PICK}.urp"
    assert cell.value("State/RobotState") == f"STOPPED {PICK}.urp"


async def test_an_unknown_program_is_not_found_and_the_robots_programs_are_listed(
    cell: Cell,
) -> None:
    with pytest.raises(CommandFailed, match="Collaboration_Fixture") as refused:
        await cell.backend.load_program("Pick")
    assert refused.value.status == "BadNotFound"


async def test_another_program_cannot_be_loaded_while_one_plays(cell: Cell) -> None:
    await cell.ready(PICK)
    with pytest.raises(CommandFailed, match="stop it"):
        await cell.backend.load_program("Collaboration_Fixture")
    await cell.backend.load_program(PICK)  # the one playing: nothing to do


async def test_play_needs_a_running_robot(cell: Cell) -> None:
    await cell.backend.load_program(PICK)
    with pytest.raises(CommandFailed, match="PowerOn"):
        await cell.backend.play()
    assert cell.value(urua.STATE_PROGRAM_STATE) == "Stopped"


async def test_play_needs_a_loaded_program(cell: Cell) -> None:
    await cell.backend.power_on()
    with pytest.raises(CommandFailed, match="No program is loaded"):
        await cell.backend.play()


async def test_play_is_refused_in_a_protective_stop(cell: Cell) -> None:
    await cell.backend.power_on()
    await cell.backend.load_program(PICK)
    await cell.space.call("Simulator/InjectFault", "protective-stop", "")
    with pytest.raises(CommandFailed, match="SAFETY_MODE_PROTECTIVE_STOP"):
        await cell.backend.play()
    assert cell.value(urua.STATE_PROGRAM_STATE) == "Stopped"


async def test_play_pause_and_stop_change_the_program_state(cell: Cell) -> None:
    await cell.ready(PICK)
    assert cell.value("State/RobotState") == f"PLAYING {PICK}.urp"
    await cell.backend.pause()
    assert cell.value(urua.STATE_PROGRAM_STATE) == "Paused"
    await cell.backend.play()
    assert cell.value(urua.STATE_PROGRAM_STATE) == "Playing"
    await cell.backend.stop_program()
    assert cell.value(urua.STATE_PROGRAM_STATE) == "Stopped"
    with pytest.raises(CommandFailed, match="nothing to pause"):
        await cell.backend.pause()


async def test_the_speed_slider_is_published_as_override_and_scaling(cell: Cell) -> None:
    await cell.backend.set_speed_override(40)
    assert cell.value("State/Override") == 40.0
    assert cell.value("State/SpeedScaling") == pytest.approx(0.4)
    for wrong in (-1.0, 100.5, float("nan")):
        with pytest.raises(CommandFailed) as refused:
            await cell.backend.set_speed_override(wrong)
        assert refused.value.status == "BadOutOfRange"


async def test_operational_mode_popup_and_log_are_kept(cell: Cell) -> None:
    await cell.backend.set_operational_mode("MANUAL")
    assert cell.value("State/OperationalMode") == "MANUAL"
    await cell.backend.set_operational_mode(None)
    assert cell.value("State/OperationalMode") == ""
    await cell.backend.popup("Wave hand to start")
    assert cell.backend.popup_message == "Wave hand to start"
    await cell.backend.popup(None)
    assert cell.backend.popup_message is None
    await cell.backend.add_to_log("cycle 3 done")
    assert list(cell.backend.log_messages) == ["cycle 3 done"]
    with pytest.raises(CommandFailed) as refused:
        await cell.backend.set_operational_mode("TURBO")
    assert refused.value.status == "BadInvalidArgument"


async def test_unlocking_needs_a_protective_stop_and_five_seconds(cell: Cell) -> None:
    with pytest.raises(CommandFailed, match="no protective stop"):
        await cell.space.call("Simulator/UnlockProtectiveStop")
    await cell.space.call("Simulator/InjectFault", "protective-stop", "")
    assert cell.value("Simulator/Fault") == "protective-stop"
    with pytest.raises(CommandFailed, match="5 s after"):
        await cell.space.call("Simulator/UnlockProtectiveStop")
    await cell.backend.clock.sleep(5.0)
    await cell.space.call("Simulator/UnlockProtectiveStop")
    assert cell.value(urua.STATE_SAFETY_MODE) == "SAFETY_MODE_NORMAL"
    assert cell.value("Simulator/Fault") == ""


async def test_faults_are_checked_and_disconnect_drops_the_clients(cell: Cell) -> None:
    with pytest.raises(CommandFailed, match="kind must be one of") as refused:
        await cell.space.call("Simulator/InjectFault", "meteor", "")
    assert refused.value.status == "BadInvalidArgument"
    with pytest.raises(CommandFailed, match="slow-steps factor") as refused:
        await cell.space.call("Simulator/InjectFault", "slow-steps", "fast")
    assert refused.value.status == "BadInvalidArgument"
    await cell.space.call("Simulator/InjectFault", "disconnect", "")
    assert cell.space.dropped == 1


async def test_input_registers_of_every_range_are_accepted_and_published(cell: Cell) -> None:
    await cell.backend.write_inputs({"Bit127": True, "Int0": -5, "Double47": 2.5})
    assert cell.value("Register/Inputs/Bitregister/Bit127") is True
    assert cell.value("Register/Inputs/Intregister/Int0") == -5
    assert cell.value("Register/Inputs/Doubleregister/Double47") == 2.5
    with pytest.raises(CommandFailed) as refused:
        await cell.backend.write_inputs({"Int3": 1, "Int48": 1})
    assert refused.value.status == "BadNodeIdUnknown"
    assert cell.backend.registers.inputs["Int3"] == 0  # nothing of a refused batch applies
