"""URUA's four-way step handshake on Bit64, emulated over the frame protocol (protocol.py).

What a URUA client sees, and what makes it happen:
1. it writes step, workspace, poses, token and input Bit64 = true in one request:
   `write` checks that a step can run now (otherwise CommandFailed and nothing is
   applied), publishes the inputs, and sends DATA×3 + RUN in the background, so
   the OPC UA write returns at once as it did with URUA;
2. when the program acknowledges the RUN frame, outputs Int24 (step), Int26/27
   (token echo) and Int28 (outcome) are published, then output Bit64 = true if
   input Bit64 is still high;
3. the client clears input Bit64 and output Bit64 falls at once: the program has
   nothing left to do, its frame was acknowledged already.
A token equal to the last one the program echoed is answered DUPLICATE (a lower
attempt of that step id STALE) without sending anything; the program fences
again on its own, over more than one token.
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
from collections.abc import Awaitable, Callable, Mapping, Sequence

from hrc_gateway import urua
from hrc_gateway.backend import CommandFailed, Publish, RegisterValue, Value
from hrc_gateway.ur import protocol
from hrc_gateway.ur.link import RobotState, StepError
from hrc_gateway.ur.protocol import Ack, Frame, StepRequest

logger = logging.getLogger(__name__)

RunFrames = Callable[[Sequence[Frame], float], Awaitable[Ack]]
CancelFrames = Callable[[], Awaitable[None]]
Ready = Callable[[], Awaitable[None]]
Report = Callable[[str], Awaitable[None]]

_OUTPUT_BIT = urua.register_path("Outputs", urua.HANDSHAKE_BIT)


def _initial(name: str) -> RegisterValue:
    return {"Bit": False, "Int": 0, "Double": 0.0}[urua.register_kind(name)]


class StepHandshake:
    def __init__(
        self,
        *,
        publish: Publish,
        run_frames: RunFrames,
        cancel_frames: CancelFrames,
        ready: Ready,
        report: Report,
        timeout: float,
    ) -> None:
        self._publish = publish
        self._run_frames = run_frames
        self._cancel_frames = cancel_frames
        self._ready = ready
        self._report = report
        self.timeout = timeout
        self.inputs: dict[str, RegisterValue] = {n: _initial(n) for n in protocol.CARRIED_INPUTS}
        self.output_bit = False
        self.last_token: tuple[int, int] | None = None
        self._lock = asyncio.Lock()
        self._in_flight: asyncio.Task[None] | None = None
        self._in_flight_request: StepRequest | None = None
        self._reported_stop = False
        self._cancelled = False
        # A RUN frame whose acknowledgement did not come in time: (its number, the step).
        self._abandoned: tuple[int, StepRequest] | None = None

    @property
    def busy(self) -> bool:
        return self._in_flight is not None and not self._in_flight.done()

    def input_values(self) -> dict[str, Value]:
        return {urua.register_path("Inputs", n): v for n, v in self.inputs.items()}

    async def adopt(self, state: RobotState) -> None:
        """Takes the last acknowledged step from the robot's registers (after a (re)connect)."""
        ack = state.ack()
        if state.out_ints[protocol.OUT_PROTOCOL] == protocol.PROTOCOL_VERSION and (
            ack.outcome != urua.OUTCOME_NONE
        ):
            self.last_token = ack.token
        await self._publish({**self._output_values(ack), _OUTPUT_BIT: self.output_bit})

    async def write(self, values: Mapping[str, RegisterValue]) -> None:
        """Applies one client write request; see the module docstring."""
        refused = [name for name in values if name not in self.inputs]
        if refused:
            raise CommandFailed(
                f"{', '.join(refused)} cannot reach the robot: ur-rtde writes no bit registers "
                f"and only input registers 42–46, so this gateway carries {protocol.CARRIED_SUMMARY} "
                "(the step handshake) and nothing else. See hrc_gateway/ur/REGISTERS.md.",
                "BadNotSupported",
            )
        async with self._lock:
            await self._apply(values)

    async def _apply(self, values: Mapping[str, RegisterValue]) -> None:
        new = {**self.inputs, **values}
        bit = urua.HANDSHAKE_BIT
        rising = bool(new[bit]) and not self.inputs[bit]
        falling = bool(self.inputs[bit]) and not new[bit]
        verdict: int | None = None
        if rising:
            if self.busy:
                raise CommandFailed(
                    "The previous step is still in flight: wait for output Bit64 before "
                    "raising input Bit64 again.",
                    "BadInvalidState",
                )
            request = StepRequest.from_inputs(new)
            verdict = protocol.fence_verdict(request.token, self.last_token)
            if verdict is None:
                await self._ready()
        self.inputs = new
        await self._publish({urua.register_path("Inputs", n): v for n, v in values.items()})
        if rising:
            if verdict is not None:
                await self._acknowledge(
                    Ack(protocol.ACK_NONE, verdict, request.step, request.token)
                )
            else:
                self._abandoned = None
                self._in_flight_request = request
                self._reported_stop = False
                self._cancelled = False
                self._in_flight = asyncio.create_task(self._run(request), name="ur-step")
        elif falling and self.output_bit:
            self.output_bit = False
            await self._publish({_OUTPUT_BIT: False})

    async def _run(self, request: StepRequest) -> None:
        frames = protocol.step_frames(request)
        try:
            ack = await self._run_frames(frames, self.timeout)
        except StepError as error:
            if error.run_seq is not None:
                self._abandoned = (error.run_seq, request)
            await self._report(self._failure_message(request, error))
            return
        await self._acknowledge(ack)

    async def observe(self, state: RobotState) -> None:
        """Watches a step in flight (a stop that suspends or ends it) and late acknowledgements."""
        if self.busy and self._in_flight_request is not None:
            await self._watch_in_flight(self._in_flight_request, state)
        elif self._abandoned is not None and state.out_ints[protocol.OUT_ACK] == self._abandoned[0]:
            request = self._abandoned[1]
            self._abandoned = None
            logger.info("Late acknowledgement of step %s (token %s)", request.step, request.token)
            await self._acknowledge(state.ack())

    async def _watch_in_flight(self, request: StepRequest, state: RobotState) -> None:
        safety = urua.SAFETY_MODES.get(state.safety_mode, str(state.safety_mode))
        program = urua.PROGRAM_STATES.get(state.runtime_state)
        if program == urua.PROGRAM_STOPPED:
            # A stopped program starts afresh and never acknowledges this frame.
            if not self._cancelled:
                self._cancelled = True
                await self._cancel_frames()
        elif safety not in urua.SAFETY_MODES_THAT_MOVE and not self._reported_stop:
            self._reported_stop = True
            await self._report(
                f"Step {request.step} (token {request.token[0]}/{request.token[1]}) is suspended: "
                f"the robot is in {safety}. A person must inspect the cell and clear it at the "
                "teach pendant; the gateway never clears a protective or emergency stop. Once the "
                "program resumes, the step finishes and is acknowledged (the gateway waits "
                f"{self.timeout:g} s in all)."
            )

    async def _acknowledge(self, ack: Ack) -> None:
        if ack.token != protocol.NO_TOKEN:
            self.last_token = ack.token
        # The echoes first, then the bit: a client that sees Bit64 finds them in place.
        await self._publish(self._output_values(ack))
        if self.inputs[urua.HANDSHAKE_BIT]:
            self.output_bit = True
            await self._publish({_OUTPUT_BIT: True})

    @staticmethod
    def _output_values(ack: Ack) -> dict[str, Value]:
        return {
            urua.register_path("Outputs", urua.STEP): ack.step,
            urua.register_path("Outputs", urua.FENCE_STEP): ack.token[0],
            urua.register_path("Outputs", urua.FENCE_ATTEMPT): ack.token[1],
            urua.register_path("Outputs", urua.OUTCOME): ack.outcome,
        }

    def _failure_message(self, request: StepRequest, error: StepError) -> str:
        what = f"Step {request.step} (token {request.token[0]}/{request.token[1]})"
        if error.reason == "timeout":
            tail = (
                " The step was sent; if it finishes later, output Bit64 still follows."
                if error.run_seq is not None
                else " The program did not take the poses: is it busy with an earlier step?"
            )
            return (
                f"{what} was not acknowledged within {self.timeout:g} s: the program is paused, "
                f"stopped or still moving.{tail}"
            )
        if error.reason == "cancelled":
            return f"{what} did not finish: the program was stopped. Output Bit64 stays false."
        return f"{what} failed: {error}. Output Bit64 stays false."

    async def close(self) -> None:
        task, self._in_flight = self._in_flight, None
        if task is not None:
            task.cancel()
            with contextlib.suppress(asyncio.CancelledError):
                await task
