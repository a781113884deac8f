"""The fake UR controller's state: robot, safety and program, registers, and the step program.

Shared by the fake RTDE and dashboard servers, and by the tests, which may
change it from their own thread: every access holds `lock`.

`StepProgram` does what hrc_gateway/ur/hrc_step_program.script does,
one controller cycle at a time, so the gateway's tests exercise the same
frame protocol a real robot runs.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Final

from hrc_gateway import urua
from hrc_gateway.ur import protocol

# RTDE robot_mode, safety_mode and runtime_state values.
POWER_OFF, POWER_ON, IDLE, RUNNING = 3, 4, 5, 7
NORMAL, PROTECTIVE_STOP, ROBOT_EMERGENCY_STOP = 1, 3, 7
STOPPED, PLAYING, PAUSED = 1, 2, 4

# How the dashboard names them (`robotmode`, `safetymode`).
DASHBOARD_ROBOT_MODES: Final = {
    -1: "NO_CONTROLLER",
    0: "DISCONNECTED",
    1: "CONFIRM_SAFETY",
    2: "BOOTING",
    3: "POWER_OFF",
    4: "POWER_ON",
    5: "IDLE",
    6: "BACKDRIVE",
    7: "RUNNING",
}
DASHBOARD_SAFETY_MODES: Final = {
    n: name.removeprefix("SAFETY_MODE_") for n, name in urua.SAFETY_MODES.items()
}

# The ring of tokens the script remembers (HRC_SEEN in the script).
SEEN_TOKENS: Final = 16


@dataclass(frozen=True)
class Execution:
    """A step the program ran (moved for)."""

    step: int
    workspace: int
    token: tuple[int, int]
    poses: tuple[float, ...]


@dataclass
class _Running:
    step: int
    workspace: int
    token: tuple[int, int]
    seq: int
    remaining: float  # seconds of motion left; inf for a step that never finishes


class StepProgram:
    """hrc_step_program.script: wait for a new frame, take it, dedupe, dispatch, echo."""

    def __init__(self, controller: FakeController) -> None:
        self.c = controller
        self.last_seq = 0
        self.poses = [0.0] * protocol.POSE_VALUES
        # The script's ring: slots of (step id, highest attempt that ran), filled round robin.
        self.seen: list[tuple[int, int] | None] = [None] * SEEN_TOKENS
        self.seen_next = 0
        self.running: _Running | None = None

    def start(self) -> None:
        """The script's preamble, when the program starts (not when it resumes)."""
        c = self.c
        self.last_seq = c.input_int(protocol.IN_SEQ)
        self.poses = [0.0] * protocol.POSE_VALUES
        self.seen = [None] * SEEN_TOKENS
        self.seen_next = 0
        self.running = None
        for register, value in (
            (protocol.OUT_PROTOCOL, protocol.PROTOCOL_VERSION),
            (protocol.OUT_STATUS, protocol.STATUS_WAITING),
            (protocol.OUT_OUTCOME, urua.OUTCOME_NONE),
            (protocol.OUT_ATTEMPT, 0),
            (protocol.OUT_STEP, 0),
            (protocol.OUT_ACK, protocol.ACK_NONE),
        ):
            c.out_ints[register] = value
        c.out_doubles[protocol.OUT_STEP_ID] = 0.0

    def cycle(self, dt: float) -> None:
        """One 2 ms cycle of a playing program."""
        if self.running is not None:
            self._move(dt)
            return
        seq = self.c.input_int(protocol.IN_SEQ)
        if seq == self.last_seq:
            return
        self.last_seq = seq
        kind = self.c.input_int(protocol.IN_KIND)
        if kind == protocol.KIND_DATA:
            self._take_data()
        elif kind == protocol.KIND_RUN:
            self._take_run(seq)
            return  # acknowledged by _finish, once the step is done
        self.c.out_ints[protocol.OUT_ACK] = seq

    def _take_data(self) -> None:
        offset = self.c.input_int(protocol.IN_ARG)
        if offset in protocol.DATA_OFFSETS:
            for j, register in enumerate(protocol.IN_VALUES):
                if offset + j < protocol.POSE_VALUES:
                    self.poses[offset + j] = self.c.input_double(register)

    def _take_run(self, seq: int) -> None:
        c = self.c
        step = c.input_int(protocol.IN_ARG)
        workspace = c.input_int(protocol.IN_WORKSPACE)
        token = (round(c.input_double(protocol.IN_STEP_ID)), c.input_int(protocol.IN_ATTEMPT))
        outcome = self._token_outcome(token)
        if outcome == 0 and step not in c.known_steps:
            outcome = urua.OUTCOME_UNKNOWN_STEP
        if outcome == 0 and workspace not in c.known_workspaces:
            outcome = urua.OUTCOME_BAD_WORKSPACE
        if outcome != 0:
            self._finish(seq, outcome, step, token)
            return
        duration = float("inf") if step in c.hang_steps else c.step_duration
        self.running = _Running(step, workspace, token, seq, duration)
        c.out_ints[protocol.OUT_STATUS] = protocol.STATUS_RUNNING

    def _move(self, dt: float) -> None:
        running = self.running
        assert running is not None
        running.remaining -= dt
        self.c.joints[0] += 0.5 * dt  # visible motion for the state mirror
        if running.remaining > 0:
            return
        self.running = None
        self.c.executions.append(
            Execution(running.step, running.workspace, running.token, tuple(self.poses))
        )
        self._remember(running.token)
        self.c.out_ints[protocol.OUT_STATUS] = protocol.STATUS_WAITING
        self._finish(running.seq, urua.OUTCOME_RAN, running.step, running.token)

    def _finish(self, seq: int, outcome: int, step: int, token: tuple[int, int]) -> None:
        c = self.c
        c.out_ints[protocol.OUT_OUTCOME] = outcome
        c.out_ints[protocol.OUT_ATTEMPT] = token[1]
        c.out_ints[protocol.OUT_STEP] = step
        c.out_doubles[protocol.OUT_STEP_ID] = float(token[0])
        c.out_ints[protocol.OUT_ACK] = seq  # last

    def _token_outcome(self, token: tuple[int, int]) -> int:
        if token == protocol.NO_TOKEN:
            return 0
        for entry in self.seen:
            if entry is not None and entry[0] == token[0]:
                if token[1] == entry[1]:
                    return urua.OUTCOME_DUPLICATE
                if token[1] < entry[1]:
                    return urua.OUTCOME_STALE
                return 0
        return 0

    def _remember(self, token: tuple[int, int]) -> None:
        if token == protocol.NO_TOKEN:
            return
        for i, entry in enumerate(self.seen):
            if entry is not None and entry[0] == token[0]:
                self.seen[i] = token
                return
        self.seen[self.seen_next] = token
        self.seen_next = (self.seen_next + 1) % SEEN_TOKENS


@dataclass
class FakeController:
    """A UR e-Series controller as far as the gateway can tell (PolyScope 5.11)."""

    lock: threading.RLock = field(default_factory=threading.RLock)
    version: tuple[int, int, int, int] = (5, 11, 5, 1010327)
    serial_number: str = "20235500123"
    robot_model: str = "UR5"
    robot_mode: int = POWER_OFF
    safety_mode: int = NORMAL
    runtime_state: int = STOPPED
    remote_control: bool = True
    operational_mode: str = "NONE"
    program_files: set[str] = field(
        default_factory=lambda: {"hrc_steps.urp", "not_hrc.urp", "pick_and_place.urp"}
    )
    # Programs built on hrc_step_program.script; the others run no frame protocol.
    step_programs: set[str] = field(default_factory=lambda: {"hrc_steps.urp", "pick_and_place.urp"})
    loaded_program: str | None = None  # a file name in /programs
    known_steps: frozenset[int] = frozenset(range(12))
    known_workspaces: frozenset[int] = frozenset(range(9))
    step_duration: float = 0.05
    hang_steps: set[int] = field(default_factory=set)
    power_on_delay: float = 0.1
    brake_release_delay: float = 0.1
    speed_slider: float = 1.0
    joints: list[float] = field(default_factory=lambda: [0.0, -1.57, 1.57, -1.57, -1.57, 0.0])
    tcp_pose: list[float] = field(default_factory=lambda: [0.4, -0.1, 0.3, 0.0, 3.14, 0.0])
    inputs: dict[str, bool | int | float] = field(default_factory=dict)
    out_ints: list[int] = field(default_factory=lambda: [0] * 48)
    out_doubles: list[float] = field(default_factory=lambda: [0.0] * 48)
    executions: list[Execution] = field(default_factory=list)
    popup_text: str | None = None
    log_messages: list[str] = field(default_factory=list)
    dashboard_commands: list[str] = field(default_factory=list)
    started_at: float = field(default_factory=time.monotonic)
    _pending: list[tuple[float, Callable[[], None]]] = field(default_factory=list)
    program: StepProgram = field(init=False)

    def __post_init__(self) -> None:
        self.program = StepProgram(self)

    # Registers --------------------------------------------------------------------

    def input_int(self, n: int) -> int:
        return int(self.inputs.get(f"input_int_register_{n}", 0))

    def input_double(self, n: int) -> float:
        return float(self.inputs.get(f"input_double_register_{n}", 0.0))

    def apply_inputs(self, values: dict[str, bool | int | float]) -> None:
        with self.lock:
            self.inputs.update(values)
            mask = values.get("speed_slider_mask")
            if isinstance(mask, int) and mask & 1:
                self.speed_slider = float(values["speed_slider_fraction"])

    # Time -----------------------------------------------------------------------------

    def tick(self, dt: float) -> None:
        with self.lock:
            now = time.monotonic()
            due = [action for when, action in self._pending if when <= now]
            self._pending = [(when, action) for when, action in self._pending if when > now]
            for action in due:
                action()
            if self.runtime_state == PLAYING and self.loaded_program in self.step_programs:
                self.program.cycle(dt)

    def after(self, delay: float, action: Callable[[], None]) -> None:
        self._pending.append((time.monotonic() + delay, action))

    # What the dashboard can do ----------------------------------------------------------

    def power_on(self) -> None:
        if self.robot_mode == POWER_OFF and self.safety_mode == NORMAL:
            self.robot_mode = POWER_ON
            self.after(self.power_on_delay, lambda: setattr(self, "robot_mode", IDLE))

    def power_off(self) -> None:
        self.robot_mode = POWER_OFF
        self.runtime_state = STOPPED

    def brake_release(self) -> None:
        if self.robot_mode == IDLE:
            self.after(self.brake_release_delay, lambda: setattr(self, "robot_mode", RUNNING))

    def play(self) -> bool:
        if (
            self.loaded_program is None
            or self.robot_mode != RUNNING
            or self.safety_mode not in (1, 2)
        ):
            return False
        if self.runtime_state != PAUSED and self.loaded_program in self.step_programs:
            self.program.start()
        self.runtime_state = PLAYING
        return True

    # Faults (a test's hand at the cell) --------------------------------------------------

    def protective_stop(self) -> None:
        """The arm hit something: the program pauses; only a person can clear it."""
        with self.lock:
            self.safety_mode = PROTECTIVE_STOP
            if self.runtime_state == PLAYING:
                self.runtime_state = PAUSED

    def clear_protective_stop(self) -> None:
        """The person at the pendant, after inspecting the cell."""
        with self.lock:
            self.safety_mode = NORMAL

    def emergency_stop(self) -> None:
        with self.lock:
            self.safety_mode = ROBOT_EMERGENCY_STOP
            self.robot_mode = POWER_OFF
            self.runtime_state = STOPPED

    def make_ready(self, program: str = "hrc_steps.urp") -> None:
        """Powered, brakes released, `program` loaded and playing: where a step can run."""
        with self.lock:
            self.robot_mode = RUNNING
            self.loaded_program = program
            self.play()

    # Outputs as RTDE streams them ---------------------------------------------------------

    def output_value(self, name: str) -> object:
        """The current value of an RTDE output field; callers hold `lock`."""
        special = self._outputs().get(name)
        if special is not None:
            return special
        if name.startswith("output_int_register_"):
            return self.out_ints[int(name.rsplit("_", 1)[1])]
        if name.startswith("output_double_register_"):
            return self.out_doubles[int(name.rsplit("_", 1)[1])]
        if name.startswith("input_"):
            return self.inputs.get(name, 0)
        return None  # the packer's zero for the field's type

    def _outputs(self) -> dict[str, object]:
        powered = self.robot_mode in (POWER_ON, IDLE, RUNNING)
        playing = self.runtime_state == PLAYING
        moving = self.program.running is not None and playing
        return {
            "timestamp": time.monotonic() - self.started_at,
            "actual_q": list(self.joints),
            "target_q": list(self.joints),
            "actual_qd": [0.5 if moving else 0.0] + [0.0] * 5,
            "actual_current": [0.4 if powered else 0.0] * 6,
            "actual_joint_voltage": [47.9 if powered else 0.0] * 6,
            "actual_TCP_pose": list(self.tcp_pose),
            "target_TCP_pose": list(self.tcp_pose),
            "actual_TCP_force": [0.0, 0.0, 1.5, 0.0, 0.0, 0.0],
            "robot_mode": self.robot_mode,
            "safety_mode": self.safety_mode,
            "runtime_state": self.runtime_state,
            "speed_scaling": self.speed_slider if playing else 0.0,
            "target_speed_fraction": self.speed_slider,
            "actual_main_voltage": 48.1,
            "actual_robot_voltage": 47.9 if powered else 0.0,
            "actual_robot_current": 0.7 if powered else 0.0,
            "robot_status_bits": int(powered) | int(playing) << 1,
            "safety_status_bits": 1 << (self.safety_mode - 1),
        }

    def ran(self, step: int | None = None) -> int:
        """How many steps ran (moved), optionally only those of `step`."""
        with self.lock:
            return sum(1 for e in self.executions if step is None or e.step == step)
