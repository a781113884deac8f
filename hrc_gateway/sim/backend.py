"""SimBackend: a simulated UR5e cell behind the gateway (`--backend sim`).

It stands in for URSim + URUA: the URUA commands, states and registers, the
prototype's seven step programs, and the cell's devices (devices.py). Test
hooks live under Simulator/: fault injection and the execution count.
"""

from __future__ import annotations

import asyncio
import collections
import contextlib
import logging
import math
import random
from collections.abc import Mapping
from dataclasses import replace
from pathlib import Path
from typing import Any, Final

from hrc_gateway import urua
from hrc_gateway.backend import (
    Backend,
    CommandFailed,
    GatewaySpace,
    Publish,
    RegisterValue,
    Value,
)
from hrc_gateway.sim import faults as fault_kinds
from hrc_gateway.sim.clock import Clock
from hrc_gateway.sim.devices import Devices
from hrc_gateway.sim.faults import Faults
from hrc_gateway.sim.fencing import REMEMBERED_STEP_IDS, ExecutionLog
from hrc_gateway.sim.programs import PROGRAMS
from hrc_gateway.sim.publisher import Publisher
from hrc_gateway.sim.registers import RegisterFile
from hrc_gateway.sim.robot import RUNNING, ArmState, Robot
from hrc_gateway.sim.runner import ProgramFault, RunnerState, StepRunner
from hrc_gateway.sim.state import CorruptState, StateFile

logger = logging.getLogger(__name__)

ROBOT_MODEL: Final = "UR5e"
FAULT: Final = "Simulator/Fault"
_KEPT_LOG_MESSAGES: Final = 200
# How long a register write may wait to be saved, coalesced with the next ones.
_COALESCED_SAVE_SECONDS: Final = 0.05


class SimBackend(Backend):
    """A simulated cobot. `time_scale` scales every duration (0: none); `state_file`
    keeps the controller's state across restarts; `seed` fixes the devices' randomness.
    """

    kind = "sim"

    def __init__(
        self,
        name: str,
        *,
        time_scale: float = 1.0,
        state_file: Path | None = None,
        seed: int | None = None,
    ) -> None:
        super().__init__(name)
        self.clock = Clock(time_scale)
        self._publish = Publisher()
        self._state_file = StateFile(state_file) if state_file is not None else None
        self.robot = Robot(self.clock, self._publish)
        self.registers = RegisterFile()
        self.log = ExecutionLog()
        self.faults = Faults(self._publish_fault)
        self.devices = Devices(self.clock, self._publish, random.Random(seed), self._persist)
        self.popup_message: str | None = None
        self.log_messages: collections.deque[str] = collections.deque(maxlen=_KEPT_LOG_MESSAGES)
        self._runner_state = RunnerState()
        self._program_task: asyncio.Task[None] | None = None
        self._space: GatewaySpace | None = None
        self._started = False
        self._closed = False
        self._save_pending: asyncio.TimerHandle | None = None

    # Lifecycle ----------------------------------------------------------------------

    async def start(self, space: GatewaySpace, publish: Publish) -> None:
        self._space = space
        self._publish.connect(publish)
        self._restore()
        self._started = True
        await self._add_simulator_nodes(space)
        await self.devices.add_nodes(space)
        await self._publish_everything()
        if self.robot.state.program_state != urua.PROGRAM_STOPPED:
            self._start_program_task()

    async def close(self) -> None:
        """Stops the program task where it is (a restart finishes its step) and saves."""
        if self._closed:
            return
        self._closed = True
        if self._save_pending is not None:
            self._save_pending.cancel()
        await self._cancel_program_task()
        if self._started:  # else the saved state was never read: keep it as it is
            await self._persist()

    async def _add_simulator_nodes(self, space: GatewaySpace) -> None:
        await space.add_method(
            "Simulator/InjectFault",
            self._inject_fault,
            [("kind", "String"), ("argument", "String")],
        )
        await space.add_method("Simulator/ClearFault", self._clear_fault)
        await space.add_method("Simulator/UnlockProtectiveStop", self._unlock_protective_stop)
        await space.add_variable("Simulator/Executions", self.log.executions)
        await space.add_variable("Simulator/ExecutedSteps", list(self.log.executed), vtype="String")
        await space.add_variable(FAULT, self._fault_text())
        await space.add_variable("Simulator/TimeScale", float(self.clock.time_scale))

    async def _publish_everything(self) -> None:
        await self.robot.publish_all(force=True)
        await self._publish(
            {
                **self.registers.published_values(),
                **self.log.published_values(),
                **self.devices.published_values(),
                FAULT: self._fault_text(),
                "Simulator/TimeScale": float(self.clock.time_scale),
            },
            force=True,
        )

    # Identity -----------------------------------------------------------------------

    async def serial_number(self) -> str:
        return f"sim-{self.name}"

    async def robot_model(self) -> str:
        return ROBOT_MODEL

    async def programs(self) -> list[str]:
        return list(PROGRAMS)

    # Commands -----------------------------------------------------------------------

    async def power_on(self) -> None:
        try:
            await self.robot.power_on()
        finally:
            await self._persist()

    async def brake_release(self) -> None:
        try:
            await self.robot.brake_release()
        finally:
            await self._persist()

    async def power_off(self) -> None:
        """Stops the program, then cuts power."""
        await self._stop_program()
        await self.robot.power_off()
        await self._persist()

    async def load_program(self, program: str) -> None:
        if program not in PROGRAMS:
            raise CommandFailed(
                f"There is no program {program!r} on the robot; it has {', '.join(PROGRAMS)}.",
                "BadNotFound",
            )
        state = self.robot.state
        if state.program == program:
            return
        if state.program_state != urua.PROGRAM_STOPPED:
            raise CommandFailed(
                f"{state.program} is {state.program_state.lower()}; stop it before loading {program}."
            )
        self.robot.tcp = PROGRAMS[program].tcp
        await self.robot.update(program=program)
        await self.robot.halt()  # the TCP pose changes with the program's TCP
        await self._persist()

    async def play(self) -> None:
        """Starts the loaded program, or resumes it where it paused."""
        state = self.robot.state
        if state.program_state == urua.PROGRAM_PLAYING:
            return
        self._check_may_play()
        program = PROGRAMS[state.program]  # type: ignore[index]  # checked above
        if state.program_state == urua.PROGRAM_STOPPED:
            self._runner_state = RunnerState(variables=program.initial_variables())
        await self.robot.update(program_state=urua.PROGRAM_PLAYING)
        if self._program_task is None:
            self._start_program_task()
        await self._persist()

    def _check_may_play(self) -> None:
        state = self.robot.state
        if state.robot_mode != RUNNING:
            raise CommandFailed(
                f"The robot is in mode {state.robot_mode!r}, not Running: power it on "
                "(PowerOn) before playing."
            )
        if state.safety_mode not in urua.SAFETY_MODES_THAT_MOVE:
            raise CommandFailed(
                f"The robot is in {state.safety_mode}: a person must check the cell and clear "
                "it at the teach pendant (Simulator/UnlockProtectiveStop), then play again."
            )
        if state.program is None:
            raise CommandFailed(f"No program is loaded: select one of {', '.join(PROGRAMS)} first.")

    async def pause(self) -> None:
        state = self.robot.state
        if state.program_state == urua.PROGRAM_PAUSED:
            return
        if state.program_state != urua.PROGRAM_PLAYING:
            raise CommandFailed("No program is playing; there is nothing to pause.")
        await self.robot.update(program_state=urua.PROGRAM_PAUSED)
        await self._persist()

    async def stop_program(self) -> None:
        """Stops the program; a step it was carrying out is abandoned (it still counts as run)."""
        await self._stop_program()
        await self._persist()

    async def set_operational_mode(self, mode: str | None) -> None:
        if mode not in ("MANUAL", "AUTOMATIC", None):
            raise CommandFailed(
                f"mode must be MANUAL, AUTOMATIC or none, not {mode!r}.", "BadInvalidArgument"
            )
        await self.robot.update(operational_mode=mode)
        await self._persist()

    async def popup(self, message: str | None) -> None:
        self.popup_message = message
        logger.info("%s popup: %s", self.name, "(closed)" if message is None else message)

    async def add_to_log(self, message: str) -> None:
        self.log_messages.append(message)
        logger.info("%s log: %s", self.name, message)

    async def write_inputs(self, values: Mapping[str, RegisterValue]) -> None:
        try:
            written = await self.registers.write_inputs(values)
        except urua.RegisterError as error:
            raise CommandFailed(str(error), error.status) from None
        await self._publish(written)
        # Saved soon, not now: the step's own saves (before moving, at the
        # acknowledgement) carry the registers; a write between them only
        # needs to reach the file eventually, coalesced with its neighbours.
        self._persist_soon()

    async def set_speed_override(self, percent: float) -> None:
        if not (math.isfinite(percent) and 0 <= percent <= 100):
            raise CommandFailed(f"The speed override is 0–100 %, not {percent}.", "BadOutOfRange")
        await self.robot.update(override=float(percent))
        await self._persist()

    async def write_variable(self, path: str, value: Value) -> None:
        if not await self.devices.write_variable(path, value):
            await super().write_variable(path, value)

    # The program task -----------------------------------------------------------------

    def _start_program_task(self) -> None:
        program = PROGRAMS[self.robot.state.program]  # type: ignore[index]
        runner = StepRunner(
            program,
            self._runner_state,
            robot=self.robot,
            registers=self.registers,
            log=self.log,
            faults=self.faults,
            publish=self._publish,
            persist=self._persist,
            step_log=self._state_file.append_step if self._state_file is not None else None,
        )
        self._program_task = asyncio.create_task(
            self._run_program(runner), name=f"sim {self.name} {program.name}"
        )

    async def _run_program(self, runner: StepRunner) -> None:
        try:
            await runner.run()
        except ProgramFault as fault:
            logger.error("%s: program stopped: %s", self.name, fault)
            await self._program_failed(str(fault))
        except Exception:
            logger.exception("%s: program %s failed", self.name, runner.program.name)
            await self._program_failed(f"{runner.program.name} failed; see the gateway's log.")

    async def _program_failed(self, message: str) -> None:
        self._program_task = None
        self._runner_state = RunnerState()
        await self.robot.update(program_state=urua.PROGRAM_STOPPED)
        await self.robot.halt()
        # Forced: the gateway clears LastError on its own, behind the publisher's back.
        await self._publish({urua.STATE_LAST_ERROR: message}, force=True)
        await self._persist()

    async def _cancel_program_task(self) -> None:
        task, self._program_task = self._program_task, None
        if task is not None and not task.done():
            task.cancel()
            with contextlib.suppress(asyncio.CancelledError):
                await task

    async def _stop_program(self) -> None:
        await self._cancel_program_task()
        self._runner_state = RunnerState()
        await self.robot.update(program_state=urua.PROGRAM_STOPPED)
        await self.robot.halt()

    # Simulator/ -----------------------------------------------------------------------

    async def _inject_fault(self, kind: str, argument: str) -> list[Value]:
        fault_kinds.check_kind(kind)
        if kind == fault_kinds.PROTECTIVE_STOP:
            await self.robot.protective_stop()
            await self._publish_fault()
            await self._persist()
        elif kind == fault_kinds.DISCONNECT:
            assert self._space is not None  # methods exist only once started
            await self._space.drop_connections()
        elif kind == fault_kinds.HANG_NEXT_STEP:
            await self.faults.arm_hang()
        else:
            await self.faults.slow_steps(fault_kinds.parse_slowdown(argument))
        return []

    async def _clear_fault(self) -> list[Value]:
        """Ends a hang and a slowdown; a protective stop needs UnlockProtectiveStop."""
        await self.faults.clear()
        return []

    async def _unlock_protective_stop(self) -> list[Value]:
        await self.robot.unlock_protective_stop()
        await self._publish_fault()
        await self._persist()
        return []

    def _fault_text(self) -> str:
        return self.faults.describe(protective_stop=self.robot.in_protective_stop)

    async def _publish_fault(self) -> None:
        await self._publish({FAULT: self._fault_text()})

    # Persistence ----------------------------------------------------------------------

    def _snapshot(self) -> dict[str, Any]:
        return {
            "arm": self.robot.state.to_dict(),
            "registers": self.registers.to_dict(),
            "log": self.log.to_dict(),
            "runner": self._runner_state.to_dict(),
            "devices": self.devices.to_dict(),
        }

    async def _persist(self) -> None:
        if self._state_file is not None:
            self._save_pending = None
            # The journal first: the snapshot must never count a step it does not know.
            entries = self.log.take_journal()
            if self._state_file.journal_lines + len(entries) > 2 * REMEMBERED_STEP_IDS:
                self._state_file.rewrite_journal(self.log.compacted_journal())
            elif entries:
                self._state_file.append_journal(entries)
            await self._state_file.save(self._snapshot())

    def _persist_soon(self) -> None:
        if self._state_file is None or self._save_pending is not None:
            return
        self._save_pending = asyncio.get_running_loop().call_later(
            _COALESCED_SAVE_SECONDS, lambda: asyncio.ensure_future(self._persist_if_pending())
        )

    async def _persist_if_pending(self) -> None:
        if self._save_pending is not None and not self._closed:
            await self._persist()

    def _restore(self) -> None:
        """Takes the saved state, if any; an unreadable one is set aside and the robot starts fresh."""
        if self._state_file is None:
            return
        try:
            data = self._state_file.load()
            if data is None:
                self._state_file.rewrite_journal([])  # a journal without its state means nothing
                return
            arm = ArmState.from_dict(data["arm"])
            if arm.program is not None and arm.program not in PROGRAMS:
                raise CorruptState(f"an unknown program {arm.program!r} is loaded")
            registers = RegisterFile()
            registers.restore(data["registers"])
            log = ExecutionLog()
            log.restore(data["log"], self._state_file.load_journal())
            runner = RunnerState.from_dict(data["runner"])
            self.devices.restore(data["devices"])
        except (CorruptState, AttributeError, KeyError, TypeError, ValueError) as error:
            aside = self._state_file.set_aside()
            self._state_file.rewrite_journal([])
            logger.warning(
                "%s: cannot read the saved state (%s); starting fresh (the file is kept as %s)",
                self.name,
                error,
                aside,
            )
            return
        self.robot.restore(arm)
        if self.robot.state.robot_mode != RUNNING or arm.program is None:
            # A program does not play on an arm that is off.
            self.robot.restore(replace(self.robot.state, program_state=urua.PROGRAM_STOPPED))
        if self.robot.state.program_state == urua.PROGRAM_STOPPED:
            runner = RunnerState()
        if arm.program is not None:
            self.robot.tcp = PROGRAMS[arm.program].tcp
        self.registers, self.log, self._runner_state = registers, log, runner
        self._state_file.rewrite_journal(log.compacted_journal())
        logger.info("%s: restored the saved state from %s", self.name, self._state_file.path)
