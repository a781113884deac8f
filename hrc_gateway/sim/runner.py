"""The running program's endless loop: the cobot side of the step handshake.

Every prototype program has the same skeleton (§4.1): wait for input Bit64
high, read the registers, act, set output Bit64, wait for input Bit64 low,
clear output Bit64. On top of it sits urua.py's fencing: the token is copied
to the outputs with an OUTCOME, and a token that already ran, or is stale,
is acknowledged without moving.

The runner's state is saved at every point of a step's life, the execution
record before the arm moves, so a gateway restart finishes an interrupted
step without running (or counting) it twice.
"""

from __future__ import annotations

import enum
import logging
import time
from collections.abc import Awaitable, Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

from hrc_gateway import urua
from hrc_gateway.sim.faults import Faults
from hrc_gateway.sim.fencing import ExecutionLog, StepRequest
from hrc_gateway.sim.kinematics import Joints, Unreachable
from hrc_gateway.sim.programs import Move, Plan, Program, Refused
from hrc_gateway.sim.publisher import Publisher
from hrc_gateway.sim.registers import RegisterFile
from hrc_gateway.sim.robot import Robot

logger = logging.getLogger(__name__)


class Phase(enum.StrEnum):
    WAITING = "waiting"  # for input Bit64 to rise
    RUNNING = "running"  # a step that counts as run is being carried out
    ACKNOWLEDGED = "acknowledged"  # output Bit64 is set; waiting for input Bit64 to fall


@dataclass
class InProgress:
    """A step being carried out: enough to plan it again and go on from `done` actions."""

    request: StepRequest
    start_joints: Joints
    variables: dict[str, int]  # the program's variables before the step
    done: int = 0

    def to_dict(self) -> dict[str, Any]:
        return {
            "request": self.request.to_dict(),
            "start_joints": list(self.start_joints),
            "variables": dict(self.variables),
            "done": self.done,
        }

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> InProgress:
        joints = tuple(float(j) for j in data["start_joints"])
        if len(joints) != 6:
            raise ValueError("not six joints")
        return cls(
            StepRequest.from_dict(data["request"]),
            joints,
            {str(k): int(v) for k, v in dict(data["variables"]).items()},
            int(data["done"]),
        )


@dataclass
class RunnerState:
    """Where the program is in its loop; saved with the controller's state."""

    phase: Phase = Phase.WAITING
    in_progress: InProgress | None = None
    variables: dict[str, int] = field(default_factory=dict)
    started: bool = False  # the program's "before start" part (OUTCOME reset) is done

    def to_dict(self) -> dict[str, Any]:
        return {
            "phase": self.phase.value,
            "in_progress": self.in_progress.to_dict() if self.in_progress else None,
            "variables": dict(self.variables),
            "started": self.started,
        }

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> RunnerState:
        phase = Phase(data["phase"])
        in_progress = InProgress.from_dict(data["in_progress"]) if data["in_progress"] else None
        if (phase == Phase.RUNNING) != (in_progress is not None):
            raise ValueError("a running phase without its step, or the other way round")
        variables = {str(k): int(v) for k, v in dict(data["variables"]).items()}
        return cls(phase, in_progress, variables, bool(data["started"]))


class ProgramFault(Exception):
    """A runtime error that stops the program, as URScript stops on an IK failure."""


class StepRunner:
    """Runs `program` on `robot` until cancelled; raises ProgramFault if the program fails."""

    def __init__(
        self,
        program: Program,
        state: RunnerState,
        *,
        robot: Robot,
        registers: RegisterFile,
        log: ExecutionLog,
        faults: Faults,
        publish: Publisher,
        persist: Callable[[], Awaitable[None]],
        step_log: Callable[[dict[str, Any]], None] | None = None,
    ) -> None:
        self.program = program
        self.state = state
        self._robot = robot
        self._registers = registers
        self._log = log
        self._faults = faults
        self._publish = publish
        self._persist = persist
        # Each step that ran, when and at what speed override (a test compares cobots' logs).
        self._step_log = step_log
        self._lowest_override = 100.0

    async def run(self) -> None:
        if not self.state.started:
            await self._robot.may_move.wait()
            reset = self._registers.write_outputs({urua.OUTCOME: urua.OUTCOME_NONE})
            self.state.started = True
            await self._persist()
            await self._publish(reset)
        if self.state.in_progress is not None:
            request = self.state.in_progress.request
            logger.info("%s: finishing step %s after a restart", self.program.name, request.token)
            await self._carry_out(self.state.in_progress)
            await self._acknowledge(request, urua.OUTCOME_RAN)
        if self.state.phase == Phase.ACKNOWLEDGED:
            await self._release()
        while True:
            request = await self._next_request()
            outcome = await self._handle(request)
            await self._acknowledge(request, outcome)
            await self._release()

    async def _next_request(self) -> StepRequest:
        """Waits for input Bit64 high while the program plays, then reads the step."""
        while True:
            await self._registers.wait_input(urua.HANDSHAKE_BIT, True)
            await self._robot.may_move.wait()
            if self._registers.inputs[urua.HANDSHAKE_BIT]:
                return StepRequest.read(self._registers)

    async def _handle(self, request: StepRequest) -> int:
        """Runs the step if it may run; returns the OUTCOME to acknowledge with."""
        verdict = self._log.verdict(request.token)
        if verdict is not None:
            logger.info("%s: token %s %s", self.program.name, request.token, urua.OUTCOMES[verdict])
            return verdict
        try:
            plan = self.program.plan(request, self._robot.state.joints, self.state.variables)
        except Refused as refused:
            self._log.saw(request.token)
            logger.info("%s: %s; nothing moved", self.program.name, refused)
            return refused.outcome
        except Unreachable as error:
            raise ProgramFault(f"{self.program.name}, step {request.step}: {error}") from None
        self._log.ran(request, self.program.name)
        self.state.phase = Phase.RUNNING
        self.state.in_progress = InProgress(
            request, self._robot.state.joints, dict(self.state.variables)
        )
        await self._persist()  # the record is on disk before the arm moves
        await self._publish(self._log.published_values())
        started, override = time.time(), self._robot.state.override
        self._lowest_override = override
        await self._carry_out(self.state.in_progress, plan)
        if self._step_log is not None:
            self._step_log({
                "token": list(request.token), "step": request.step, "program": self.program.name,
                "started": started, "ended": time.time(), "override": override,
                "lowest_override": self._lowest_override,
                "override_at_end": self._robot.state.override,
            })  # fmt: skip
        return urua.OUTCOME_RAN

    async def _carry_out(self, step: InProgress, plan: Plan | None = None) -> None:
        """Carries out the step's actions from the first not yet done."""
        if plan is None:
            try:
                plan = self.program.plan(step.request, step.start_joints, step.variables)
            except (Refused, Unreachable) as error:  # only if the program changed meanwhile
                raise ProgramFault(f"{self.program.name}: cannot finish step: {error}") from None
        for index in range(step.done, len(plan.actions)):
            action = plan.actions[index]
            if isinstance(action, Move):
                await self._robot.move(
                    action.target,
                    linear=action.linear,
                    speed=action.speed,
                    acceleration=action.acceleration,
                    slowdown=self._faults.slowdown,
                )
            else:
                await self._robot.dwell(action.seconds, slowdown=self._faults.slowdown)
            self._lowest_override = min(self._lowest_override, self._robot.state.override)
            step.done = index + 1
            if step.done < len(plan.actions):  # after the last, the acknowledgement saves
                await self._persist()
        await self._faults.hang_if_armed()
        self.state.variables = dict(plan.variables)

    async def _acknowledge(self, request: StepRequest, outcome: int) -> None:
        await self._robot.may_move.wait()
        step_id, attempt = request.token
        echo = self._registers.write_outputs(
            {
                urua.FENCE_STEP: step_id,
                urua.FENCE_ATTEMPT: attempt,
                urua.STEP: request.step,
                urua.OUTCOME: outcome,
            }
        )
        bit = self._registers.write_outputs({urua.HANDSHAKE_BIT: True})
        self.state.phase = Phase.ACKNOWLEDGED
        self.state.in_progress = None
        # Saved before a client can see it: no acknowledgement the robot could forget.
        await self._persist()
        await self._publish(echo)
        # The bit goes out after the echo, so a client that sees it reads the right token.
        await self._publish(bit)

    async def _release(self) -> None:
        await self._registers.wait_input(urua.HANDSHAKE_BIT, False)
        await self._robot.may_move.wait()
        bit = self._registers.write_outputs({urua.HANDSHAKE_BIT: False})
        self.state.phase = Phase.WAITING
        # Not saved: a restart in the acknowledged phase just releases again, harmlessly,
        # and a step costs one save fewer.
        await self._publish(bit)
