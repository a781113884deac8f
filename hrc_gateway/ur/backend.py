"""The `ur-rtde` backend: a real Universal Robots controller through ur-rtde.

Three channels, none of which stops the robot's own program:
- RTDE (port 30004) through a worker process (rtde_worker.py, link.py) that
  owns RTDEReceiveInterface (state, output registers) and RTDEIOInterface
  (input registers 42–46, speed slider), both in the upper register range;
- the dashboard server (port 29999) through DashboardClient (dashboard.py) for
  power, programs, popups and the log;
- never RTDEControlInterface: it stops the running program and uploads its own.

URUA's step handshake is emulated over numbered frames (handshake.py,
protocol.py, REGISTERS.md); the robot runs hrc_step_program.script.

The gateway never clears a protective or emergency stop: it does not send
`unlock protective stop`, `close safety popup` or `restart safety`.
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
import time
from collections.abc import Mapping, Sequence
from typing import ClassVar

from hrc_gateway import urua
from hrc_gateway.backend import (
    Backend,
    CommandFailed,
    GatewaySpace,
    Publish,
    RegisterValue,
    Value,
)
from hrc_gateway.ur import protocol
from hrc_gateway.ur.dashboard import Dashboard, DashboardUnavailable
from hrc_gateway.ur.handshake import StepHandshake
from hrc_gateway.ur.link import LinkError, RobotState, RTDELink, StepError
from hrc_gateway.ur.protocol import Ack, Frame

logger = logging.getLogger(__name__)

RTDE_PORT = 30004  # fixed: ur-rtde's interfaces take no port argument
CONNECT_TIMEOUT = 10.0
DASHBOARD_POLL = 1.0
MODE_POLL = 0.1  # while waiting for a robot mode during power on
BACKOFF_FIRST, BACKOFF_MAX = 0.25, 10.0
# Dashboard robot modes, as `robotmode` names them.
DASHBOARD_IDLE, DASHBOARD_RUNNING = "IDLE", "RUNNING"
# Safety modes (dashboard `safetymode` names) that need a person at the pendant.
_PENDANT_STOPS = frozenset({"PROTECTIVE_STOP", "ROBOT_EMERGENCY_STOP", "SYSTEM_EMERGENCY_STOP"})
_MOVING_SAFETY = frozenset({"NORMAL", "REDUCED"})

_AXES = tuple(f"Axis{n}" for n in range(1, 7))
# (folder, vector variable, RobotState field) as in URUA's address space (§1.2).
_VECTORS = (
    ("Axes/ActualPositions", "AxisPositions", "actual_q"),
    ("Axes/ActualVelocities", "AxisVelocities", "actual_qd"),
    ("Axes/ActualCurrents", "AxisCurrents", "actual_current"),
    ("Axes/ActualVoltage", "AxisVoltage", "actual_joint_voltage"),
    ("Tcp/ActualPose", "TCPPose", "actual_tcp_pose"),  # the TCP pose, unlike URUA
    ("Tcp/ActualSpeed", "TCPSpeed", "actual_tcp_speed"),
    ("Tcp/ActualForce", "TCPForce", "actual_tcp_force"),
)


class URBackend(Backend):
    """A UR e-Series (or CB3 ≥ 3.9) controller at `robot_host`.

    `programs` lists the base names SelectProgram offers: the dashboard cannot
    list the robot's files, so they come from the cobot's configuration.
    `command_timeout` bounds power on, each wait for a robot mode and a step.
    """

    kind: ClassVar[str] = "ur-rtde"

    def __init__(
        self,
        name: str,
        *,
        robot_host: str,
        dashboard_port: int = 29999,
        frequency: float = 500.0,
        command_timeout: float = 30.0,
        programs: Sequence[str] = (),
    ) -> None:
        super().__init__(name)
        self.robot_host = robot_host
        self.frequency = frequency
        self.command_timeout = command_timeout
        self._programs = [urua.program_base_name(p) for p in programs]
        self._dashboard = Dashboard(robot_host, dashboard_port)
        self._link: RTDELink | None = None
        self._state: RobotState | None = None
        self._published: dict[str, Value] = {}
        self._publish_to: Publish | None = None
        self._tasks: list[asyncio.Task[None]] = []
        self._rtde_lost = asyncio.Event()
        self._dashboard_lost = asyncio.Event()
        self._serial = ""
        self._model = ""
        self._closed = False
        self.handshake = StepHandshake(
            publish=self._publish,
            run_frames=self._run_frames,
            cancel_frames=self._cancel_frames,
            ready=self._step_ready,
            report=self._report,
            timeout=command_timeout,
        )

    # Lifecycle -----------------------------------------------------------------

    async def start(self, space: GatewaySpace, publish: Publish) -> None:
        self._publish_to = publish
        try:
            await self._dashboard.connect()
            self._serial = await self._dashboard.call("get serial number")
            self._model = await self._dashboard.call("get robot model")
        except DashboardUnavailable as error:
            await self.close()
            raise CommandFailed(str(error), "BadCommunicationError") from None
        try:
            await self._connect_rtde()
        except LinkError as error:
            await self.close()
            raise CommandFailed(self._link_failure(error), _link_status(error)) from None
        await self._publish(self.handshake.input_values())
        await self._poll_dashboard()
        self._tasks = [
            asyncio.create_task(self._keep_rtde(), name=f"ur-rtde-{self.name}"),
            asyncio.create_task(self._keep_dashboard(), name=f"ur-dashboard-{self.name}"),
        ]

    async def close(self) -> None:
        self._closed = True
        await self.handshake.close()
        for task in self._tasks:
            task.cancel()
        for task in self._tasks:
            with contextlib.suppress(asyncio.CancelledError):
                await task
        self._tasks = []
        if self._link is not None:
            await self._link.close()
            self._link = None
        await self._dashboard.close()

    @property
    def rtde_connected(self) -> bool:
        return self._link is not None and self._link.connected

    @property
    def dashboard_connected(self) -> bool:
        return self._dashboard.connected

    # Identity --------------------------------------------------------------------

    async def serial_number(self) -> str:
        return self._serial

    async def robot_model(self) -> str:
        return self._model

    async def programs(self) -> list[str]:
        """The configured programs (the dashboard has no command that lists files)."""
        return list(self._programs)

    # Commands ----------------------------------------------------------------------

    async def power_on(self) -> None:
        await self._refuse_in_safety_stop("Power on")
        mode = await self._robot_mode()
        if mode == DASHBOARD_RUNNING:
            return
        if mode != DASHBOARD_IDLE:
            await self._command("power on", "Powering on", "Power on")
            await self._wait_for_mode(DASHBOARD_IDLE, "Power on")
        await self._release_brakes()

    async def brake_release(self) -> None:
        await self._refuse_in_safety_stop("Brake release")
        mode = await self._robot_mode()
        if mode == DASHBOARD_RUNNING:
            return
        if mode != DASHBOARD_IDLE:
            raise CommandFailed(
                f"Brake release refused: the robot is {mode}; the brakes are released from "
                "IDLE. Power it on first (PowerOn releases the brakes as well).",
                "BadInvalidState",
            )
        await self._release_brakes()

    async def _release_brakes(self) -> None:
        await self._command("brake release", "Brake releasing", "Brake release")
        await self._wait_for_mode(DASHBOARD_RUNNING, "Brake release")

    async def power_off(self) -> None:
        await self._command("power off", "Powering off", "Power off")

    async def load_program(self, program: str) -> None:
        name = _one_line(program, "A program name")
        reply = await self._call(f"load {name}.urp")
        if reply.startswith("Loading program"):
            await self._refresh_dashboard_state()
            return
        if reply.startswith("File not found"):
            raise CommandFailed(
                f"The robot has no program {name}.urp in its programs folder. Dashboard: {reply!r}",
                "BadNotFound",
            )
        raise await self._refusal("Load program", reply)

    async def play(self) -> None:
        await self._refuse_in_safety_stop("Play")
        await self._command("play", "Starting program", "Play")
        await self._refresh_dashboard_state()

    async def pause(self) -> None:
        await self._command("pause", "Pausing program", "Pause")
        await self._refresh_dashboard_state()

    async def stop_program(self) -> None:
        await self._command("stop", "Stopped", "Stop")
        await self._refresh_dashboard_state()

    async def set_operational_mode(self, mode: str | None) -> None:
        if mode is None:
            await self._command("clear operational mode", "No longer controlling", "Clear mode")
            return
        if mode not in ("MANUAL", "AUTOMATIC"):
            raise CommandFailed(
                f"Operational mode {mode!r}: use MANUAL or AUTOMATIC.", "BadInvalidArgument"
            )
        await self._command(
            f"set operational mode {mode.lower()}", "Operational mode", "Set operational mode"
        )

    async def popup(self, message: str | None) -> None:
        if message is None:
            await self._command("close popup", "closing popup", "Close popup")
        else:
            text = _one_line(message, "A popup message")
            await self._command(f"popup {text}", "showing popup", "Popup")

    async def add_to_log(self, message: str) -> None:
        text = _one_line(message, "A log message")
        await self._command(f"addToLog {text}", "Added log message", "Add to log")

    async def write_inputs(self, values: Mapping[str, RegisterValue]) -> None:
        await self.handshake.write(values)

    async def set_speed_override(self, percent: float) -> None:
        if not 0.0 <= percent <= 100.0:
            raise CommandFailed(f"The speed override is 0–100 %, not {percent:g}.", "BadOutOfRange")
        link = self._require_link()
        try:
            await link.set_speed_slider(percent / 100.0, timeout=5.0)
        except LinkError as error:
            raise CommandFailed(str(error), "BadCommunicationError") from None

    # RTDE ----------------------------------------------------------------------------

    async def _connect_rtde(self) -> None:
        link = RTDELink(
            self.robot_host,
            frequency=self.frequency,
            on_state=self._on_state,
            on_lost=self._on_lost,
        )
        state = await link.connect(CONNECT_TIMEOUT)
        self._link = link
        self._rtde_lost.clear()
        await self.handshake.adopt(state)
        await self._on_state(state)

    async def _keep_rtde(self) -> None:
        """Reconnects after a loss, backing off; the robot mode reads Disconnected meanwhile."""
        while not self._closed:
            await self._rtde_lost.wait()
            delay = BACKOFF_FIRST
            while not self._closed:
                if self._link is not None:
                    await self._link.close()
                    self._link = None
                try:
                    await self._connect_rtde()
                except LinkError as error:
                    await self._report(f"Reconnecting RTDE: {self._link_failure(error)}")
                    await asyncio.sleep(delay)
                    delay = min(delay * 2, BACKOFF_MAX)
                    continue
                logger.info("RTDE connection to %s restored", self.robot_host)
                break

    async def _on_lost(self, message: str) -> None:
        self._state = None
        await self._publish({urua.STATE_ROBOT_MODE: urua.ROBOT_MODES[0]})
        await self._report(f"The RTDE connection to {self.robot_host} dropped: {message}")
        self._rtde_lost.set()

    async def _on_state(self, state: RobotState) -> None:
        self._state = state
        await self._publish(_state_values(state))
        await self.handshake.observe(state)

    def _require_link(self) -> RTDELink:
        link = self._link
        if link is None or not link.connected:
            raise CommandFailed(
                f"There is no RTDE connection to the robot at {self.robot_host}:{RTDE_PORT}; "
                "the gateway is reconnecting in the background.",
                "BadCommunicationError",
            )
        return link

    async def _run_frames(self, frames: Sequence[Frame], timeout: float) -> Ack:
        link = self._link
        if link is None:
            raise StepError("The RTDE connection dropped.", "lost")
        return await link.run_frames(frames, timeout)

    async def _cancel_frames(self) -> None:
        with contextlib.suppress(LinkError):
            if self._link is not None:
                await self._link.cancel_frames()

    async def _step_ready(self) -> None:
        """CommandFailed unless a step written now would run."""
        self._require_link()
        state = self._state
        if state is None:
            raise CommandFailed("The robot's state is not known yet.", "BadCommunicationError")
        safety = urua.SAFETY_MODES.get(state.safety_mode, str(state.safety_mode))
        if safety not in urua.SAFETY_MODES_THAT_MOVE:
            raise CommandFailed(_safety_refusal("A step", safety), "BadInvalidState")
        program = urua.PROGRAM_STATES.get(state.runtime_state, str(state.runtime_state))
        if program != urua.PROGRAM_PLAYING:
            raise CommandFailed(
                f"The robot program is {program}, not Playing: a step written now would not run. "
                "Load and start the HRC step program first.",
                "BadInvalidState",
            )
        version = state.out_ints[protocol.OUT_PROTOCOL]
        if version != protocol.PROTOCOL_VERSION:
            raise CommandFailed(
                f"The running program does not speak the HRC frame protocol (output int register "
                f"41 is {version}, not {protocol.PROTOCOL_VERSION}): run a program built on "
                "hrc_step_program.script (see hrc_gateway/ur/REGISTERS.md).",
                "BadInvalidState",
            )

    def _link_failure(self, error: LinkError) -> str:
        if error.in_use:
            return (
                f"Another RTDE client or a fieldbus adapter (EtherNet/IP, PROFINET, MODBUS) owns "
                f"input registers this gateway needs on {self.robot_host} (input int 42–47, "
                "input double 42–46, the speed slider and the output masks ur-rtde's "
                "RTDEIOInterface claims). Only one process per cobot may write RTDE inputs: stop "
                f"the other client or disable the adapter. ur-rtde said: {error}"
            )
        return f"No RTDE connection to {self.robot_host}:{RTDE_PORT}: {error}"

    # Dashboard ----------------------------------------------------------------------

    async def _keep_dashboard(self) -> None:
        """Polls the dashboard state every second; reconnects with back-off when it drops."""
        delay = BACKOFF_FIRST
        while not self._closed:
            try:
                if not self._dashboard.connected:
                    await self._dashboard.connect()
                    logger.info("Dashboard connection to %s made", self._dashboard.address)
                await self._poll_dashboard()
            except (DashboardUnavailable, CommandFailed) as error:
                await self._report(f"Reconnecting the dashboard: {error}")
                await asyncio.sleep(delay)
                delay = min(delay * 2, BACKOFF_MAX)
                continue
            delay = BACKOFF_FIRST
            await asyncio.sleep(DASHBOARD_POLL)

    async def _poll_dashboard(self) -> None:
        loaded = await self._call("get loaded program")
        program_state = await self._call("programState")
        remote = await self._call("is in remote control")
        mode = await self._call("get operational mode")
        await self._publish(
            {
                urua.STATE_CURRENT_PROGRAM: loaded.removeprefix("Loaded program:").strip()
                if loaded.startswith("Loaded program:")
                else "",
                "State/RobotState": program_state,
                "State/Remote": remote.strip().lower() == "true",
                "State/OperationalMode": mode if mode in ("MANUAL", "AUTOMATIC") else "",
            }
        )

    async def _refresh_dashboard_state(self) -> None:
        """Polls now rather than within the second: a client that loaded a program reads
        State/CurrentProgram next. The command itself succeeded, so a failure here is moot."""
        with contextlib.suppress(CommandFailed):
            await self._poll_dashboard()

    async def _call(self, command: str) -> str:
        try:
            return await self._dashboard.call(command)
        except DashboardUnavailable as error:
            raise CommandFailed(
                f"{error} The gateway is reconnecting in the background; try again.",
                "BadCommunicationError",
            ) from None

    async def _command(self, command: str, success: str, action: str) -> None:
        reply = await self._call(command)
        if not reply.startswith(success):
            raise await self._refusal(action, reply)

    async def _refusal(self, action: str, reply: str) -> CommandFailed:
        """Explains a dashboard refusal: Local Control is the usual cause on e-Series."""
        with contextlib.suppress(CommandFailed):
            if (await self._call("is in remote control")).lower() == "false":
                return CommandFailed(
                    f"{action} refused: the robot is in Local Control. Switch it to Remote Control "
                    f"on the teach pendant; the dashboard accepts no commands otherwise. "
                    f"Dashboard: {reply!r}",
                    "BadInvalidState",
                )
        return CommandFailed(
            f"{action} refused by the robot. Dashboard: {reply!r}", "BadInvalidState"
        )

    async def _refuse_in_safety_stop(self, action: str) -> None:
        reply = await self._call("safetymode")
        mode = reply.removeprefix("Safetymode:").strip()
        if mode not in _MOVING_SAFETY:
            raise CommandFailed(_safety_refusal(action, f"SAFETY_MODE_{mode}"), "BadInvalidState")

    async def _robot_mode(self) -> str:
        return (await self._call("robotmode")).removeprefix("Robotmode:").strip()

    async def _wait_for_mode(self, wanted: str, action: str) -> None:
        deadline = time.monotonic() + self.command_timeout
        while (mode := await self._robot_mode()) != wanted:
            if time.monotonic() > deadline:
                raise CommandFailed(
                    f"{action}: the robot did not reach {wanted} within "
                    f"{self.command_timeout:g} s (it is {mode}).",
                    "BadTimeout",
                )
            await self._refuse_in_safety_stop(action)
            await asyncio.sleep(MODE_POLL)

    # Publishing ------------------------------------------------------------------------

    async def _publish(self, values: Mapping[str, Value]) -> None:
        """Publishes the values that changed since the last publish."""
        changed = {k: v for k, v in values.items() if self._published.get(k, _UNSET) != v}
        if not changed or self._publish_to is None:
            return
        self._published.update(changed)
        await self._publish_to(changed)

    async def _report(self, message: str) -> None:
        """Publishes a message in State/LastError, even a repeated one: the server clears
        LastError after each successful call, behind this backend's back."""
        logger.warning("%s: %s", self.name, message)
        self._published[urua.STATE_LAST_ERROR] = message
        if self._publish_to is not None:
            await self._publish_to({urua.STATE_LAST_ERROR: message})


_UNSET = object()


def _link_status(error: LinkError) -> str:
    return "BadResourceUnavailable" if error.in_use else "BadCommunicationError"


def _safety_refusal(action: str, safety: str) -> str:
    if safety.removeprefix("SAFETY_MODE_") in _PENDANT_STOPS:
        return (
            f"{action} refused: the robot is in {safety}. A person must inspect the cell and "
            "clear the stop at the teach pendant; the software never clears a protective or "
            "emergency stop."
        )
    return (
        f"{action} refused: the robot is in {safety}, in which it may not move. "
        "Resolve it at the cell (e.g. close the safeguard) and the teach pendant."
    )


def _one_line(text: str, what: str) -> str:
    if any(ch in text for ch in "\r\n\0"):
        # The dashboard reads one command per line: a line break would start another command.
        raise CommandFailed(f"{what} must be one line.", "BadInvalidArgument")
    return text.strip()


def _state_values(state: RobotState) -> dict[str, Value]:
    values: dict[str, Value] = {
        urua.STATE_ROBOT_MODE: urua.ROBOT_MODES.get(state.robot_mode, str(state.robot_mode)),
        urua.STATE_SAFETY_MODE: urua.SAFETY_MODES.get(state.safety_mode, str(state.safety_mode)),
        urua.STATE_PROGRAM_STATE: urua.PROGRAM_STATES.get(
            state.runtime_state, str(state.runtime_state)
        ),
        "State/SpeedScaling": state.speed_scaling,
        "State/Override": state.target_speed_fraction * 100.0,
        "SafetyBoard/MainVoltage": state.main_voltage,
        "SafetyBoard/RobotVoltage": state.robot_voltage,
        "SafetyBoard/RobotCurrent": state.robot_current,
        "Axes/ActualMomentum/AxisMomentum": state.actual_momentum,
    }
    for folder, vector, field in _VECTORS:
        numbers: list[float] = list(getattr(state, field))
        values[f"{folder}/{vector}"] = numbers
        values.update({f"{folder}/{axis}": v for axis, v in zip(_AXES, numbers, strict=True)})
    # The protocol's real registers, for diagnosis; the emulated ones come from the handshake.
    for n, v in state.out_ints.items():
        values[urua.register_path("Outputs", f"Int{n}")] = v
    for n, d in state.out_doubles.items():
        values[urua.register_path("Outputs", f"Double{n}")] = d
    return values
