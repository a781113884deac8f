"""The step programs: what each does, and the handshake with fencing token and OUTCOME."""

import asyncio
from dataclasses import dataclass

import pytest

from hrc_gateway import urua
from hrc_gateway.backend import CommandFailed
from hrc_gateway.sim import kinematics, programs
from hrc_gateway.sim.kinematics import HOME, pose_trans
from tests.gateway.sim.cell import ZERO_POSE, Ack, Cell, is_moving, out

POSITION_TOLERANCE = 1e-5  # metres
ROTATION_TOLERANCE = 1e-5  # radians
FIXTURE = "Collaboration_Fixture"


@dataclass(frozen=True)
class Case:
    program: str
    step: int
    workspace: int = 0
    pose: tuple[float, ...] = ZERO_POSE
    second_pose: tuple[float, ...] = ZERO_POSE
    visits: tuple[tuple[float, ...], ...] = ()  # TCP poses published on the way (end of a move)
    ends: tuple[float, ...] | None = None  # the TCP pose at the end; None: at home


TAPE = (0.01, 0.02, 0.03, 0.0, 0.0, 0.0)
PART = (0.2, 0.25, 0.05, 0.0, 0.0, 0.0)
LINE_START = (0.0, 0.1, 0.0, 0.0, 0.0, 0.0)
LINE_END = (0.4, 0.1, 0.0, 0.0, 0.0, 0.0)

CASES = [
    Case(
        "Synchronized_SpotTaping",
        0,
        pose=TAPE,
        visits=(pose_trans(programs.SPOT_WORKSPACE1, TAPE),),
    ),
    Case(
        "Synchronized_SpotTaping2Op",
        0,
        workspace=1,
        pose=TAPE,
        visits=(pose_trans(programs.SPOT_2OP_WORKSPACE2, TAPE),),
    ),
    Case(
        "Coexistence_PickAndPlace",
        2,
        workspace=0,
        pose=PART,
        ends=pose_trans(programs.PARTBOX, PART),
    ),
    Case(
        "Cooperation_QualityInspection",
        2,
        workspace=3,
        visits=(programs.INSPECTION_WAIT_POS,),
        ends=programs.INSPECTION_SPOTS[3],
    ),
    Case(
        "Cooperation_Polishing",
        2,
        pose=LINE_START,
        second_pose=LINE_END,
        visits=(pose_trans(programs.POLISHING_SURFACE, LINE_END),),
        ends=pose_trans(programs.POLISHING_SURFACE, LINE_START),
    ),
    Case(FIXTURE, 3, workspace=2, ends=programs.FIXTURE_MOUNTS[2]),
    Case(
        "Collaboration_CollaborativeAssembly",
        3,
        visits=(programs.BOTTOM_PLATE,),
        ends=programs.PLATE_HANDOVER,
    ),
]


def reached(cell: Cell, target: tuple[float, ...], poses: list[list[float]]) -> bool:
    for pose in poses:
        metres, radians = kinematics.pose_distance(pose, target)
        if metres < POSITION_TOLERANCE and radians < ROTATION_TOLERANCE:
            return True
    return False


@pytest.mark.parametrize("case", CASES, ids=[case.program for case in CASES])
async def test_each_program_moves_the_arm_to_its_targets(cell: Cell, case: Case) -> None:
    await cell.ready(case.program)
    mark = cell.recorder.mark()
    ack = await cell.step(
        case.step, workspace=case.workspace, pose=case.pose, second_pose=case.second_pose
    )
    assert ack.outcome == urua.OUTCOME_RAN
    # It moved over time rather than jumping: every motion sample carries the
    # velocity since the last one. (Counting intermediate positions instead
    # depends on the machine: a loaded loop samples a 40 ms move only at its end.)
    velocities = cell.recorder.since(mark, "Axes/ActualVelocities/AxisVelocities")
    assert any(is_moving(v) for v in velocities)
    poses = cell.recorder.since(mark, "Tcp/ActualPose/TCPPose")
    for target in case.visits:
        assert reached(cell, target, poses)  # type: ignore[arg-type]
    final = cell.joints
    tcp = programs.PROGRAMS[case.program].tcp
    expected = case.ends if case.ends is not None else kinematics.forward(HOME, tcp)
    assert reached(cell, expected, [list(kinematics.forward(final, tcp))])
    assert reached(cell, expected, [cell.value("Tcp/ActualPose/TCPPose")])  # type: ignore[list-item]
    assert cell.value("Axes/ActualVelocities/AxisVelocities") == [0.0] * 6


async def test_a_step_that_ran_is_acknowledged_with_its_token_step_and_outcome(
    cell: Cell,
) -> None:
    await cell.ready(FIXTURE)
    await cell.send(1, token=(41, 1))
    ack = await cell.acknowledged()
    assert ack == Ack((41, 1), 1, urua.OUTCOME_RAN)
    # The echo is out before the bit rises, so a client reading on the bit reads it.
    bit_at = next(
        i for i, (_, c) in enumerate(cell.recorder.history) if c.get(out("Bit64")) is True
    )
    outcome_at = max(i for i, (_, c) in enumerate(cell.recorder.history) if out(urua.OUTCOME) in c)
    assert outcome_at < bit_at
    assert cell.value(out("Bit64")) is True  # held until the client lets go
    await asyncio.sleep(0.05)
    assert cell.value(out("Bit64")) is True
    await cell.release()
    assert cell.value("Simulator/Executions") == 1
    assert cell.value("Simulator/ExecutedSteps") == [f"41.1 step=1 program={FIXTURE}"]


async def test_the_same_token_again_is_a_duplicate_and_does_not_move(cell: Cell) -> None:
    await cell.ready(FIXTURE)
    await cell.step(3, workspace=1, token=(7, 1))
    mark = cell.recorder.mark()
    ack = await cell.step(3, workspace=4, token=(7, 1))
    assert ack == Ack((7, 1), 3, urua.OUTCOME_DUPLICATE)
    assert cell.recorder.since(mark, "Axes/ActualPositions/AxisPositions") == []
    assert cell.value("Simulator/Executions") == 1


async def test_a_lower_attempt_of_a_step_id_seen_is_stale(cell: Cell) -> None:
    await cell.ready(FIXTURE)
    await cell.step(3, workspace=1, token=(8, 2))
    ack = await cell.step(3, workspace=1, token=(8, 1))
    assert ack.outcome == urua.OUTCOME_STALE
    ack = await cell.step(3, workspace=2, token=(8, 3))  # a newer attempt runs
    assert ack.outcome == urua.OUTCOME_RAN
    assert cell.value("Simulator/Executions") == 2


async def test_a_step_the_program_lacks_is_acknowledged_as_unknown(cell: Cell) -> None:
    await cell.ready(FIXTURE)
    mark = cell.recorder.mark()
    ack = await cell.step(9, token=(9, 1))
    assert ack == Ack((9, 1), 9, urua.OUTCOME_UNKNOWN_STEP)
    assert cell.recorder.since(mark, "Axes/ActualPositions/AxisPositions") == []
    assert cell.value("Simulator/Executions") == 0


async def test_a_workspace_the_program_lacks_is_refused_without_moving(cell: Cell) -> None:
    await cell.ready(FIXTURE)
    mark = cell.recorder.mark()
    ack = await cell.step(3, workspace=7, token=(10, 1))
    assert ack.outcome == urua.OUTCOME_BAD_WORKSPACE
    assert cell.recorder.since(mark, "Axes/ActualPositions/AxisPositions") == []
    ack = await cell.step(3, workspace=6, token=(10, 2))  # corrected by the next attempt
    assert ack.outcome == urua.OUTCOME_RAN


async def test_without_a_token_every_step_runs_as_in_the_prototype(cell: Cell) -> None:
    await cell.ready(FIXTURE)
    assert cell.value(out(urua.OUTCOME)) == urua.OUTCOME_NONE
    for _ in range(2):
        ack = await cell.step(3, workspace=5)
        assert ack == Ack((0, 0), 3, urua.OUTCOME_RAN)
    assert cell.value("Simulator/Executions") == 2


async def test_pausing_freezes_the_arm_mid_move_and_play_resumes_it(cell: Cell) -> None:
    await cell.ready(FIXTURE)
    await cell.send(2, token=(11, 1))
    await cell.moving()
    await cell.backend.pause()
    frozen = cell.joints
    assert cell.value("Axes/ActualVelocities/AxisVelocities") == [0.0] * 6
    await asyncio.sleep(0.15)
    assert cell.joints == frozen
    await cell.backend.play()
    assert (await cell.acknowledged()).outcome == urua.OUTCOME_RAN
    assert cell.joints != frozen


async def test_a_protective_stop_halts_a_step_until_unlocked_and_played(cell: Cell) -> None:
    await cell.ready(FIXTURE)
    await cell.send(2, token=(12, 1))
    await cell.moving()
    await cell.space.call("Simulator/InjectFault", "protective-stop", "")
    assert cell.value(urua.STATE_SAFETY_MODE) == "SAFETY_MODE_PROTECTIVE_STOP"
    assert cell.value(urua.STATE_PROGRAM_STATE) == "Paused"
    frozen = cell.joints
    with pytest.raises(CommandFailed, match="teach pendant"):
        await cell.backend.play()
    await cell.backend.clock.sleep(5.0)
    await cell.space.call("Simulator/UnlockProtectiveStop")
    await asyncio.sleep(0.1)  # unlocked, but the program waits for play
    assert cell.value(urua.STATE_PROGRAM_STATE) == "Paused"
    assert cell.joints == frozen
    assert cell.value(out("Bit64")) is False
    await cell.backend.play()
    ack = await cell.acknowledged()
    assert ack.outcome == urua.OUTCOME_RAN
    assert cell.value("Simulator/Executions") == 1


async def test_a_hung_step_finishes_only_when_the_fault_is_cleared(cell: Cell) -> None:
    await cell.ready(FIXTURE)
    await cell.space.call("Simulator/InjectFault", "hang-next-step", "")
    await cell.send(1, token=(13, 1))
    with pytest.raises(TimeoutError):
        await cell.acknowledged(timeout=0.3)
    assert cell.value("Simulator/Fault") == "hang-next-step"
    assert cell.value("Simulator/Executions") == 1  # it ran; it just never finishes
    await cell.space.call("Simulator/ClearFault")
    assert (await cell.acknowledged()).outcome == urua.OUTCOME_RAN
    assert cell.value("Simulator/Fault") == ""


async def test_slow_steps_make_a_step_take_longer(cell: Cell) -> None:
    await cell.ready(FIXTURE)
    loop = asyncio.get_running_loop()
    started = loop.time()
    await cell.step(3, workspace=1)
    await cell.step(1)
    normal = loop.time() - started
    await cell.space.call("Simulator/InjectFault", "slow-steps", "4")
    assert cell.value("Simulator/Fault") == "slow-steps 4"
    started = loop.time()
    await cell.step(3, workspace=1)
    await cell.step(1)
    assert loop.time() - started > 2 * normal


async def test_a_speed_override_of_zero_holds_the_arm(cell: Cell) -> None:
    await cell.ready(FIXTURE)
    await cell.send(2, token=(14, 1))
    await cell.moving()
    await cell.backend.set_speed_override(0)
    await asyncio.sleep(0.03)
    held = cell.joints
    await asyncio.sleep(0.1)
    assert cell.joints == held
    await cell.backend.set_speed_override(100)
    assert (await cell.acknowledged()).outcome == urua.OUTCOME_RAN


async def test_stopping_abandons_the_step_which_still_counts_as_run(cell: Cell) -> None:
    await cell.ready(FIXTURE)
    await cell.send(2, token=(15, 1))
    await cell.moving()
    await cell.backend.stop_program()
    assert cell.value("Axes/ActualVelocities/AxisVelocities") == [0.0] * 6
    await cell.backend.play()  # starts over; the client still holds Bit64 with the same token
    ack = await cell.acknowledged()
    assert ack.outcome == urua.OUTCOME_DUPLICATE
    assert cell.value("Simulator/Executions") == 1


async def test_a_pose_out_of_reach_stops_the_program_with_an_error(cell: Cell) -> None:
    await cell.ready("Coexistence_PickAndPlace")
    await cell.send(2, token=(16, 1), pose=(2.0, 2.0, 0.0, 0.0, 0.0, 0.0))
    await cell.recorder.wait_for(urua.STATE_PROGRAM_STATE, "Stopped")
    assert "inverse kinematics" in str(cell.value(urua.STATE_LAST_ERROR))
    assert cell.value("Simulator/Executions") == 0
    assert cell.value(out("Bit64")) is False


async def test_the_assembly_program_remembers_which_side_it_inspected(cell: Cell) -> None:
    await cell.ready("Collaboration_CollaborativeAssembly")
    await cell.step(8)  # qualityCheck = 2: the front was inspected
    await cell.step(0)
    await cell.step(1)  # rework: hold the box as for the front plate
    assert reached(cell, programs.ASSEMBLY_HOLDS[2], [cell.value("Tcp/ActualPose/TCPPose")])  # type: ignore[list-item]
    mark = cell.recorder.mark()
    await cell.step(1)  # qualityCheck was reset: nothing to hold
    assert cell.recorder.since(mark, "Axes/ActualPositions/AxisPositions") == []
