"""The prototype's seven URSim programs (prototype-artefacts §4.2), as step plans.

A program turns one step request into a plan: the moves and tool waits its
"act" branch carries out, with every target already solved to joints. The
plan is a pure function of the request, the joints the step starts from and
the program's variables, so a step interrupted by a gateway restart is
planned again identically and finished from the action it had reached.

Feature poses are §4.2's where it gives them. Where it gives none (the eight
inspection spots, Fixture's orientations, the assembly waypoints) they are
invented but plausible, inside a UR5e's reach, and marked so.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Final

from hrc_gateway import urua
from hrc_gateway.sim import kinematics
from hrc_gateway.sim.fencing import StepRequest
from hrc_gateway.sim.kinematics import HOME, TCP, Joints, Pose, pose_trans
from hrc_gateway.sim.robot import MOVEJ_ACCELERATION, MOVEJ_SPEED

# MoveL in the prototype's programs, m/s and m/s² (§4.1); Polishing is gentler.
MOVEL_SPEED: Final = 0.25
MOVEL_ACCELERATION: Final = 1.2
POLISH_SPEED: Final = 0.1
POLISH_ACCELERATION: Final = 0.5
# The simulated tool actions (taping, gripping, placing) are 2 s waits.
TOOL_SECONDS: Final = 2.0

_HALF_PI: Final = math.pi / 2
# Orientations under the programs' flipped TCP (kinematics.TCP): a feature with
# no rotation has the flange pointing down; this one has it pointing ahead (+x).
_FACING_AHEAD: Final = (0.0, -_HALF_PI, 0.0)


@dataclass(frozen=True)
class Move:
    target: Joints
    linear: bool
    speed: float
    acceleration: float


@dataclass(frozen=True)
class Dwell:
    seconds: float


Action = Move | Dwell


@dataclass(frozen=True)
class Plan:
    actions: tuple[Action, ...]
    variables: Mapping[str, int]  # the program's variables once the step has run


class Refused(Exception):
    """The program does nothing for this request: `outcome` is OUTCOME_UNKNOWN_STEP or _BAD_WORKSPACE."""

    def __init__(self, outcome: int, reason: str) -> None:
        super().__init__(reason)
        self.outcome = outcome


def unknown_step(request: StepRequest) -> Refused:
    return Refused(urua.OUTCOME_UNKNOWN_STEP, f"the program has no step {request.step}")


def bad_workspace(request: StepRequest) -> Refused:
    return Refused(
        urua.OUTCOME_BAD_WORKSPACE,
        f"step {request.step} knows no workspace {request.workspace}",
    )


class Arm:
    """Records a step's statements as actions, tracking where the arm will be after each."""

    def __init__(self, joints: Joints, tcp: Pose) -> None:
        self.joints = joints
        self.tcp = tcp
        self.actions: list[Action] = []

    @property
    def pose(self) -> Pose:
        return kinematics.forward(self.joints, self.tcp)

    def movej(self, pose: Pose) -> None:
        """MoveJ to a TCP pose (kinematics.Unreachable if no joints reach it)."""
        self.movej_joints(kinematics.inverse(pose, self.joints, self.tcp))

    def movej_joints(self, joints: Joints) -> None:
        self.actions.append(Move(joints, False, MOVEJ_SPEED, MOVEJ_ACCELERATION))
        self.joints = joints

    def movel(
        self, pose: Pose, speed: float = MOVEL_SPEED, acceleration: float = MOVEL_ACCELERATION
    ) -> None:
        joints = kinematics.inverse(pose, self.joints, self.tcp)
        self.actions.append(Move(joints, True, speed, acceleration))
        self.joints = joints

    def wait(self, seconds: float = TOOL_SECONDS) -> None:
        self.actions.append(Dwell(seconds))

    def home(self) -> None:
        self.movej_joints(HOME)


# A program's "act" branch: plans the step on `arm`, may change `variables`,
# raises Refused when it does nothing.
Body = Callable[[StepRequest, Arm, dict[str, int]], None]


@dataclass(frozen=True)
class Program:
    name: str
    body: Body
    tcp: Pose = TCP
    variables: Mapping[str, int] | None = None  # initial values, set when the program starts

    def initial_variables(self) -> dict[str, int]:
        return dict(self.variables or {})

    def plan(self, request: StepRequest, joints: Joints, variables: Mapping[str, int]) -> Plan:
        """The step's actions from `joints`; Refused or kinematics.Unreachable when it cannot run."""
        arm = Arm(joints, self.tcp)
        changed = dict(variables)
        self.body(request, arm, changed)
        return Plan(tuple(arm.actions), changed)


def _along_z(pose: Pose, feature: Pose, metres: float) -> Pose:
    """`pose` moved `metres` along the feature's z axis."""
    z = [row[2] for row in kinematics.rotation_matrix((feature[3], feature[4], feature[5]))]
    return (pose[0] + metres * z[0], pose[1] + metres * z[1], pose[2] + metres * z[2], *pose[3:])


def _p(*values: float) -> Pose:
    return tuple(float(v) for v in values)  # type: ignore[return-value]


# Synchronized_SpotTaping(2Op) -----------------------------------------------------

SPOT_WORKSPACE1: Final = _p(0.489, -0.133, 0.240, 0, -0.524, 0)
# The two-operator variant: workspace 1 selects Workspace2, anything else Workspace1.
SPOT_2OP_WORKSPACE1: Final = _p(0.489, 0.3, 0.240, 0, -0.524, 0)
SPOT_2OP_WORKSPACE2: Final = _p(0.489, -0.3, 0.240, 0, -0.524, 0)


def _tape(arm: Arm, workspace: Pose, request: StepRequest) -> None:
    arm.movel(pose_trans(workspace, _p(*request.pose)))
    arm.wait()  # taping
    arm.home()


def spot_taping(request: StepRequest, arm: Arm, variables: dict[str, int]) -> None:
    # No step register: every handshake tapes one spot.
    _tape(arm, SPOT_WORKSPACE1, request)


def spot_taping_2op(request: StepRequest, arm: Arm, variables: dict[str, int]) -> None:
    workspace = SPOT_2OP_WORKSPACE2 if request.workspace == 1 else SPOT_2OP_WORKSPACE1
    _tape(arm, workspace, request)


# Coexistence_PickAndPlace ------------------------------------------------------------

PARTBOX: Final = _p(0.3, -0.4, 0, 0, 0, 0)
PLACE_LOCATION: Final = _p(0, 0.5, 0.3, 0, 0, 0)


def pick_and_place(request: StepRequest, arm: Arm, variables: dict[str, int]) -> None:
    match request.step:
        case 1:
            arm.home()
        case 2:
            feature = {0: PARTBOX, 1: PLACE_LOCATION}.get(request.workspace)
            if feature is None:
                raise bad_workspace(request)
            arm.movej(pose_trans(feature, _p(*request.pose)))
        case 3:
            arm.wait()  # pick
        case 4:
            arm.movel(_along_z(arm.pose, PARTBOX, 0.20))  # lift
        case 5:
            arm.wait()  # place
            arm.movel(_along_z(arm.pose, PLACE_LOCATION, 0.10))
        case _:
            raise unknown_step(request)


# Cooperation_QualityInspection ------------------------------------------------------

# Invented (the installation's poses are not in §4.2): the back face of the
# inspected part stands 0.6 m ahead; "Left" spots lie at +y, "Right" at -y,
# "Bot" 0.15 m and "Top" 0.45 m high; the camera (TCP) looks at it (+x).
# Workspaces 1–4 are cobot1's, 5–8 cobot2's; both run the same installation.
INSPECTION_SPOTS: Final = {
    1: _p(0.6, 0.30, 0.15, *_FACING_AHEAD),  # BackLeftBot_1
    2: _p(0.6, 0.15, 0.15, *_FACING_AHEAD),  # BackLeftBot_2
    3: _p(0.6, 0.30, 0.45, *_FACING_AHEAD),  # BackLeftTop_1
    4: _p(0.6, 0.15, 0.45, *_FACING_AHEAD),  # BackLeftTop_2
    5: _p(0.6, -0.15, 0.15, *_FACING_AHEAD),  # BackRightBot_1
    6: _p(0.6, -0.30, 0.15, *_FACING_AHEAD),  # BackRightBot_2
    7: _p(0.6, -0.15, 0.45, *_FACING_AHEAD),  # BackRightTop_1
    8: _p(0.6, -0.30, 0.45, *_FACING_AHEAD),  # BackRightTop_2
}
INSPECTION_WAIT_POS: Final = _p(0.4, 0.0, 0.35, *_FACING_AHEAD)  # invented


def quality_inspection(request: StepRequest, arm: Arm, variables: dict[str, int]) -> None:
    match request.step:
        case 1:
            arm.home()
        case 2:
            spot = INSPECTION_SPOTS.get(request.workspace)
            if spot is None:
                raise bad_workspace(request)
            arm.movel(INSPECTION_WAIT_POS)
            arm.movel(pose_trans(spot, _p(*request.pose)))
        case _:
            raise unknown_step(request)


# Cooperation_Polishing -----------------------------------------------------------------

# §4.2's Surface is p[0.65, -0.35, 0.85, 0, π, 0]: 0.85 m high is beyond a
# UR5e's reach (its TCP would be ~1 m from the shoulder), so the surface is
# lowered to 0.40 m; x, y and orientation are kept. Its rotation (0, π, 0) is
# the usual tool-down pose with an unrotated TCP, which Polishing uses (§4.1:
# the flipped TCP only "where set").
POLISHING_SURFACE: Final = _p(0.65, -0.35, 0.40, 0, math.pi, 0)
POLISHING_TCP: Final = _p(0, 0, 0.1, 0, 0, 0)


def polishing(request: StepRequest, arm: Arm, variables: dict[str, int]) -> None:
    match request.step:
        case 1:
            arm.home()
        case 2:
            start = pose_trans(POLISHING_SURFACE, _p(*request.pose))
            end = pose_trans(POLISHING_SURFACE, _p(*request.second_pose))
            for pose in (start, end, start):
                arm.movel(pose, POLISH_SPEED, POLISH_ACCELERATION)
        case _:
            raise unknown_step(request)


# Collaboration_Fixture -------------------------------------------------------------------

FIXTURE_GRAB_OFFSET: Final = _p(0, 0.5, 0.35, 0, 0, 0)
FIXTURE_GRAB: Final = _p(0, 0.5, 0.30, 0, 0, 0)
# Positions from §4.2; left to right as the operator, facing the robot, sees
# them (y falling). Orientation invented: the part is held out towards the fixture.
FIXTURE_MOUNTS: Final = {
    workspace: _p(0.70, y, z, *_FACING_AHEAD)
    for workspace, (y, z) in enumerate(
        [(y, z) for z in (0.55, 0.35) for y in (-0.30, -0.133, 0.10)], start=1
    )
}  # 1 TopL, 2 TopM, 3 TopR, 4 BotL, 5 BotM, 6 BotR


def fixture(request: StepRequest, arm: Arm, variables: dict[str, int]) -> None:
    match request.step:
        case 1:
            arm.home()
        case 2:
            arm.movej(FIXTURE_GRAB_OFFSET)
            arm.movel(FIXTURE_GRAB)
            arm.wait()  # grip
            arm.movel(FIXTURE_GRAB_OFFSET)
            arm.home()
        case 3:
            mount = FIXTURE_MOUNTS.get(request.workspace)
            if mount is None:
                raise bad_workspace(request)
            arm.movej(mount)
        case _:
            raise unknown_step(request)


# Collaboration_CollaborativeAssembly ------------------------------------------------------

ASSEMBLY_WORKSPACE: Final = _p(0.4, -0.3, 0.1, 0, 0, 0)


def _in_workspace(*offset: float) -> Pose:
    return pose_trans(ASSEMBLY_WORKSPACE, _p(*offset))


# Invented waypoints (§4.2 names them only), relative to Workspace1: parts on
# the table, the box beside them, handovers and the held box towards the
# operator (+y), tilted so the side being worked on faces them.
_ABOVE: Final = 0.10
SCREWS: Final = _in_workspace(0.0, 0.0, 0.02, 0, 0, 0)
BOTTOM_PLATE: Final = _in_workspace(0.10, 0.0, 0.01, 0, 0, 0)
FRONT_PLATE: Final = _in_workspace(0.10, 0.12, 0.01, 0, 0, 0)
TOP_PLATE: Final = _in_workspace(0.0, 0.12, 0.01, 0, 0, 0)
BOX: Final = _in_workspace(-0.10, 0.25, 0.05, 0, 0, 0)
SCREW_HANDOVER: Final = _in_workspace(0.20, 0.30, 0.25, 0, 0, 0)
PLATE_HANDOVER: Final = _in_workspace(0.20, 0.40, 0.25, 0, 0, 0)
ASSEMBLY_HOLDS: Final = {  # by qualityCheck: 1 bottom, 2 front, 3 top
    1: _in_workspace(0.15, 0.35, 0.30, 0, 0.6, 0),
    2: _in_workspace(0.15, 0.35, 0.30, 0, 0, 0),
    3: _in_workspace(0.15, 0.35, 0.25, 0, 0, _HALF_PI),
}
SCAN_POSES: Final = {
    1: _in_workspace(0.0, 0.45, 0.40, 0, 0.6, 0),
    2: _in_workspace(0.0, 0.45, 0.40, 0, 0, 0),
    3: _in_workspace(0.0, 0.45, 0.35, 0, 0, _HALF_PI),
}


def _pick(arm: Arm, place: Pose) -> None:
    """Above the place, down, grip (or release), up again."""
    above = _along_z(place, ASSEMBLY_WORKSPACE, _ABOVE)
    arm.movej(above)
    arm.movel(place)
    arm.wait()
    arm.movel(above)


def collaborative_assembly(request: StepRequest, arm: Arm, variables: dict[str, int]) -> None:
    step = request.step
    if step == 0:
        arm.home()
    elif step == 1:  # rework: hold the box where the failed inspection saw it
        held = ASSEMBLY_HOLDS.get(variables["qualityCheck"])
        if held is not None:
            arm.movej(held)
        variables["qualityCheck"] = 0
    elif step == 2:
        _pick(arm, SCREWS)
        arm.movej(SCREW_HANDOVER)
    elif step == 3:
        _pick(arm, BOTTOM_PLATE)
        arm.movej(PLATE_HANDOVER)
    elif step in (4, 7, 10):  # grab the box and hold it for the next plate
        _pick(arm, BOX)
        arm.movej(ASSEMBLY_HOLDS[(step - 1) // 3])
    elif step in (5, 8, 11):  # show the side just assembled to the camera
        variables["qualityCheck"] = (step - 2) // 3
        arm.movej(SCAN_POSES[variables["qualityCheck"]])
    elif step in (6, 9):  # put the box aside, fetch the next plate
        _pick(arm, BOX)
        _pick(arm, FRONT_PLATE if step == 6 else TOP_PLATE)
        arm.movej(PLATE_HANDOVER)
    else:
        raise unknown_step(request)


PROGRAMS: Final = {
    program.name: program
    for program in (
        Program("Synchronized_SpotTaping", spot_taping),
        Program("Synchronized_SpotTaping2Op", spot_taping_2op),
        Program("Coexistence_PickAndPlace", pick_and_place),
        Program("Cooperation_QualityInspection", quality_inspection),
        Program("Cooperation_Polishing", polishing, tcp=POLISHING_TCP),
        Program("Collaboration_Fixture", fixture),
        Program(
            "Collaboration_CollaborativeAssembly",
            collaborative_assembly,
            variables={"qualityCheck": 0},
        ),
    )
}
