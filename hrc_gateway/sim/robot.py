"""The simulated arm and its controller: power, safety, program state, joints and motion.

What a UR e-series controller does, as far as a client of the gateway can
tell: the power-on sequence, a protective stop that only a person can clear,
program states, and joints that move over time at MoveJ/MoveL speeds, freeze
when the program pauses or the robot stops, and follow the speed slider.
Which program runs, and when, is the backend's business (backend.py).
"""

from __future__ import annotations

import asyncio
import math
from collections.abc import Awaitable, Callable, Mapping
from dataclasses import asdict, dataclass, replace
from typing import Any, Final

from hrc_gateway import urua
from hrc_gateway.backend import CommandFailed, Value
from hrc_gateway.sim import kinematics
from hrc_gateway.sim.clock import Clock
from hrc_gateway.sim.kinematics import HOME, TCP, Joints, Pose, Profile
from hrc_gateway.sim.publisher import Publisher

POWER_OFF: Final = urua.ROBOT_MODE_POWER_OFF
POWER_ON: Final = urua.ROBOT_MODES[4]
BOOTING: Final = urua.ROBOT_MODES[2]
IDLE: Final = urua.ROBOT_MODE_IDLE
RUNNING: Final = urua.ROBOT_MODE_RUNNING
PROTECTIVE_STOP: Final = urua.SAFETY_MODES[3]

# Robot seconds the controller spends in each power-on stage (a real e-series
# takes a few seconds; short enough here not to slow a demo down).
POWER_ON_SECONDS: Final = 0.2
BOOT_SECONDS: Final = 0.8
BRAKE_RELEASE_SECONDS: Final = 0.5
# A UR controller refuses to unlock a protective stop sooner than this after it.
UNLOCK_DELAY_SECONDS: Final = 5.0

# MoveJ's speed and acceleration in the prototype's programs (§4.1), rad/s and rad/s²;
# also the limit on the tool's rotation during MoveL.
MOVEJ_SPEED: Final = 1.047
MOVEJ_ACCELERATION: Final = 1.396

# Where URSim keeps programs: what "get loaded program" reports.
PROGRAM_FOLDER: Final = "/programs"

# RTDE joint modes by robot mode; the tool follows the joints.
_JOINT_MODES: Final = {
    POWER_OFF: "JOINT_POWER_OFF_MODE",
    POWER_ON: "JOINT_BOOTING_MODE",
    BOOTING: "JOINT_BOOTING_MODE",
    IDLE: "JOINT_IDLE_MODE",
    RUNNING: "JOINT_RUNNING_MODE",
}
# Safety board readings: 48 V bus; the arm draws more while it moves.
_MAIN_VOLTAGE: Final = 48.0
_IDLE_CURRENT: Final = {POWER_OFF: 0.0, POWER_ON: 0.3, BOOTING: 0.5, IDLE: 0.6, RUNNING: 0.9}
_CURRENT_PER_RAD_S: Final = 1.2

AXES: Final = tuple(f"Axis{n}" for n in range(1, 7))
ZERO6: Final = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)


@dataclass
class ArmState:
    """What the controller keeps across a gateway restart."""

    robot_mode: str = POWER_OFF
    safety_mode: str = urua.SAFETY_NORMAL
    program_state: str = urua.PROGRAM_STOPPED
    program: str | None = None
    joints: Joints = HOME
    override: float = 100.0
    operational_mode: str | None = "AUTOMATIC"

    def to_dict(self) -> dict[str, Any]:
        return {**asdict(self), "joints": list(self.joints)}

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> ArmState:
        """The state saved by to_dict; ValueError/KeyError/TypeError when it is not one."""
        joints = tuple(float(j) for j in data["joints"])
        state = cls(
            robot_mode=str(data["robot_mode"]),
            safety_mode=str(data["safety_mode"]),
            program_state=str(data["program_state"]),
            program=None if data["program"] is None else str(data["program"]),
            joints=joints,  # type: ignore[arg-type]
            override=float(data["override"]),
            operational_mode=data["operational_mode"],
        )
        if (
            len(joints) != 6
            or not all(math.isfinite(j) for j in joints)
            or state.robot_mode not in urua.ROBOT_MODES.values()
            or state.safety_mode not in urua.SAFETY_MODES.values()
            or state.program_state not in urua.PROGRAM_STATES.values()
            or not 0 <= state.override <= 100
            or state.operational_mode not in ("MANUAL", "AUTOMATIC", None)
        ):
            raise ValueError("not a saved arm state")
        return state


def move_profile(
    start: Joints, target: Joints, tcp: Pose, linear: bool, speed: float, acceleration: float
) -> Profile:
    """The motion profile of a move from `start` to `target`: MoveJ by the joint that turns
    furthest, MoveL by the TCP's travel or turn, whichever takes longer."""
    if not linear:
        furthest = max(abs(b - a) for a, b in zip(start, target, strict=True))
        return Profile(furthest, speed, acceleration)
    metres, radians = kinematics.pose_distance(
        kinematics.forward(start, tcp), kinematics.forward(target, tcp)
    )
    travel = Profile(metres, speed, acceleration)
    turn = Profile(radians, MOVEJ_SPEED, MOVEJ_ACCELERATION)
    return max(travel, turn, key=lambda p: p.duration)


# Called with (profile seconds elapsed, robot seconds since the last sample).
Sample = Callable[[float, float], Awaitable[None]]


class Robot:
    """The arm: publishes every state change and every motion sample through `publish`."""

    def __init__(self, clock: Clock, publish: Publisher) -> None:
        self.clock = clock
        self._publish = publish
        self.state = ArmState()
        self.tcp: Pose = TCP
        self.velocities: Joints = ZERO6
        self._tcp_speed: Pose = ZERO6
        # Set while the program may act: powered, brakes released, safe, playing.
        self.may_move = asyncio.Event()
        self._power_lock = asyncio.Lock()
        self._power_generation = 0
        self._protective_stop_at: float | None = None

    def restore(self, state: ArmState) -> None:
        """Takes a saved state; a controller caught half-way through powering on is off."""
        if state.robot_mode not in (IDLE, RUNNING):
            state = replace(state, robot_mode=POWER_OFF)
        self.state = state
        self._refresh_gate()

    # State ------------------------------------------------------------------------

    @property
    def powered(self) -> bool:
        return self.state.robot_mode != POWER_OFF

    @property
    def in_protective_stop(self) -> bool:
        return self.state.safety_mode == PROTECTIVE_STOP

    async def update(self, **changes: Any) -> None:
        """Changes ArmState fields and publishes the state; the arm stops at once if it must."""
        could_move = self.may_move.is_set()
        self.state = replace(self.state, **changes)
        self._refresh_gate()
        if could_move and not self.may_move.is_set():
            await self.halt()
        else:
            await self._publish(self.state_values())

    def _refresh_gate(self) -> None:
        s = self.state
        if (
            s.robot_mode == RUNNING
            and s.safety_mode in urua.SAFETY_MODES_THAT_MOVE
            and s.program_state == urua.PROGRAM_PLAYING
        ):
            self.may_move.set()
        else:
            self.may_move.clear()

    def state_values(self) -> dict[str, Value]:
        s = self.state
        urp = f"{s.program}.urp" if s.program else "<unnamed>"
        moving = sum(abs(v) for v in self.velocities)
        return {
            urua.STATE_ROBOT_MODE: s.robot_mode,
            urua.STATE_SAFETY_MODE: s.safety_mode,
            urua.STATE_PROGRAM_STATE: s.program_state,
            urua.STATE_CURRENT_PROGRAM: f"{PROGRAM_FOLDER}/{urp}" if s.program else "",
            # The dashboard's programState reply, as URUA passed it on.
            "State/RobotState": f"{s.program_state.upper()} {urp}",
            "State/JointMode": _JOINT_MODES.get(s.robot_mode, "JOINT_POWER_OFF_MODE"),
            "State/ToolMode": _JOINT_MODES.get(s.robot_mode, "JOINT_POWER_OFF_MODE"),
            "State/SpeedScaling": s.override / 100,
            "State/Remote": True,
            "State/OperationalMode": s.operational_mode or "",
            "State/Override": s.override,
            "SafetyBoard/MainVoltage": _MAIN_VOLTAGE,
            "SafetyBoard/RobotVoltage": _MAIN_VOLTAGE if self.powered else 0.0,
            "SafetyBoard/RobotCurrent": round(
                _IDLE_CURRENT.get(s.robot_mode, 0.0) + _CURRENT_PER_RAD_S * moving, 3
            ),
        }

    def motion_values(self) -> dict[str, Value]:
        q = list(self.state.joints)
        pose = list(kinematics.forward(q, self.tcp))
        values: dict[str, Value] = {
            "Axes/ActualPositions/AxisPositions": q,
            "Axes/ActualVelocities/AxisVelocities": list(self.velocities),
            "Tcp/ActualPose/TCPPose": pose,
            "Tcp/ActualSpeed/TCPSpeed": list(self._tcp_speed),
        }
        for i, axis in enumerate(AXES):
            values[f"Axes/ActualPositions/{axis}"] = q[i]
            values[f"Axes/ActualVelocities/{axis}"] = self.velocities[i]
            values[f"Tcp/ActualPose/{axis}"] = pose[i]
            values[f"Tcp/ActualSpeed/{axis}"] = self._tcp_speed[i]
        return values

    async def publish_all(self, *, force: bool = False) -> None:
        await self._publish({**self.state_values(), **self.motion_values()}, force=force)

    # Power and safety -------------------------------------------------------------

    async def power_on(self) -> None:
        """Powers on, boots to Idle and releases the brakes; returns when Running.

        Raises CommandFailed when the robot is in a protective stop (then or
        on the way), or is powered off while powering on.
        """
        self._check_safe_to_power()
        async with self._power_lock:
            generation = self._power_generation
            if self.state.robot_mode not in (IDLE, RUNNING):
                await self.update(robot_mode=POWER_ON)
                await self._power_stage(POWER_ON_SECONDS, generation)
                await self.update(robot_mode=BOOTING)
                await self._power_stage(BOOT_SECONDS, generation)
                await self.update(robot_mode=IDLE)
            if self.state.robot_mode == IDLE:
                await self._release_brakes(generation)

    async def brake_release(self) -> None:
        """Releases the brakes of an arm powered on to Idle; returns when Running.

        Raises CommandFailed in a protective stop, or when the arm is not
        Idle (powered off, booting); an arm already Running is left as it is.
        """
        self._check_safe_to_power()
        async with self._power_lock:
            mode = self.state.robot_mode
            if mode == RUNNING:
                return
            if mode != IDLE:
                raise CommandFailed(
                    f"The robot is in mode {mode!r}; the brakes are released from Idle. "
                    "Power it on first (PowerOn releases the brakes as well)."
                )
            await self._release_brakes(self._power_generation)

    async def _release_brakes(self, generation: int) -> None:
        # The brakes click open one joint after another.
        await self._power_stage(BRAKE_RELEASE_SECONDS, generation)
        await self.update(robot_mode=RUNNING)

    async def _power_stage(self, seconds: float, generation: int) -> None:
        await self.clock.sleep(seconds)
        if generation != self._power_generation:
            raise CommandFailed("The robot was powered off while it was powering on.")
        self._check_safe_to_power()

    def _check_safe_to_power(self) -> None:
        if self.state.safety_mode not in urua.SAFETY_MODES_THAT_MOVE:
            raise CommandFailed(
                f"The robot is in {self.state.safety_mode}. A person must check the cell and "
                "clear it at the teach pendant (in the simulator: Simulator/UnlockProtectiveStop), "
                "then power on again."
            )

    async def power_off(self) -> None:
        """Cuts power to the arm (the caller stops the program first)."""
        self._power_generation += 1
        await self.halt()
        await self.update(robot_mode=POWER_OFF)

    async def protective_stop(self) -> None:
        """The arm stops where it is; a playing program pauses. Idempotent."""
        if self.in_protective_stop:
            return
        self._protective_stop_at = self.clock.now()
        program_state = self.state.program_state
        if program_state == urua.PROGRAM_PLAYING:
            program_state = urua.PROGRAM_PAUSED
        await self.update(safety_mode=PROTECTIVE_STOP, program_state=program_state)
        await self.halt()

    async def unlock_protective_stop(self) -> None:
        """What the person at the teach pendant does; the program stays paused until played."""
        if not self.in_protective_stop:
            raise CommandFailed("There is no protective stop to unlock.")
        if self._protective_stop_at is not None and not self.clock.instant:
            waited = self.clock.robot_seconds(self.clock.now() - self._protective_stop_at)
            if waited < UNLOCK_DELAY_SECONDS:
                raise CommandFailed(
                    f"A protective stop can be unlocked {UNLOCK_DELAY_SECONDS:.0f} s after it "
                    f"happened; wait {UNLOCK_DELAY_SECONDS - waited:.1f} s more."
                )
        self._protective_stop_at = None
        await self.update(safety_mode=urua.SAFETY_NORMAL)

    # Motion -----------------------------------------------------------------------

    async def move(
        self,
        target: Joints,
        *,
        linear: bool,
        speed: float,
        acceleration: float,
        slowdown: float = 1.0,
    ) -> None:
        """Moves the joints from where they are to `target`; returns once there.

        MoveJ (`linear` False) times the move by the joint that turns furthest,
        MoveL by the TCP's travel (m) and turn. Both interpolate in joint space
        between the endpoints, so a simulated MoveL does not keep the TCP on a
        straight line; the endpoints and the timing are what a client sees.
        Freezes while `may_move` is clear; takes `slowdown` times longer.
        """
        start = self.state.joints
        profile = self._profile(start, target, linear, speed, acceleration)

        async def sample(elapsed: float, robot_dt: float) -> None:
            s = profile.fraction(elapsed)
            q = tuple(a + (b - a) * s for a, b in zip(start, target, strict=True))
            await self._set_joints(q, robot_dt)  # type: ignore[arg-type]

        await self._advance(profile.duration, sample, follows_override=True, slowdown=slowdown)
        self.state.joints = target
        await self.halt()

    def _profile(
        self, start: Joints, target: Joints, linear: bool, speed: float, acceleration: float
    ) -> Profile:
        return move_profile(start, target, self.tcp, linear, speed, acceleration)

    async def dwell(self, seconds: float, *, slowdown: float = 1.0) -> None:
        """A program's sleep: `seconds` of robot time, frozen while the program is held."""

        async def nothing(elapsed: float, robot_dt: float) -> None:
            return None

        await self._advance(seconds, nothing, follows_override=False, slowdown=slowdown)

    async def _advance(
        self, duration: float, sample: Sample, *, follows_override: bool, slowdown: float
    ) -> None:
        """Lets `duration` seconds of program time pass while `may_move` is set.

        Program time runs at the speed slider's fraction (when
        `follows_override`) divided by `slowdown`; `sample` is called about
        every 40 ms of robot time, never more often than every 10 ms of wall time.
        """
        if duration <= 0 or self.clock.instant:
            await self.may_move.wait()
            await sample(duration, 0.0)
            return
        elapsed = 0.0
        last = self.clock.now()
        while elapsed < duration:
            if not self.may_move.is_set():
                await self.halt()
                await self.may_move.wait()
                last = self.clock.now()
                continue
            await asyncio.sleep(self.clock.sample_period)
            now = self.clock.now()
            if self.may_move.is_set():
                robot_dt = self.clock.robot_seconds(now - last)
                rate = (self.state.override / 100 if follows_override else 1.0) / slowdown
                elapsed = min(duration, elapsed + robot_dt * rate)
                await sample(elapsed, robot_dt)
            last = now

    async def _set_joints(self, q: Joints, robot_dt: float) -> None:
        before, pose_before = self.state.joints, kinematics.forward(self.state.joints, self.tcp)
        self.state.joints = q
        if robot_dt > 0:
            self.velocities = tuple((b - a) / robot_dt for a, b in zip(before, q, strict=True))  # type: ignore[assignment]
            self._tcp_speed = kinematics.tcp_velocity(
                pose_before, kinematics.forward(q, self.tcp), robot_dt
            )
        await self._publish({**self.motion_values(), **self.state_values()})

    async def halt(self) -> None:
        """Publishes the arm at rest where it is (after a move, a stop or a cancelled task)."""
        self.velocities = ZERO6
        self._tcp_speed = ZERO6
        await self._publish({**self.motion_values(), **self.state_values()})
