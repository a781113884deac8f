"""The gateway's end of the ur-rtde worker process (rtde_worker.py): start, ask, kill.

Every wait has a deadline; when one passes, the worker is killed rather than
trusted, and the backend reconnects by starting a new one.
"""

from __future__ import annotations

import asyncio
import collections
import contextlib
import itertools
import json
import logging
import os
import sys
from collections.abc import Awaitable, Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from hrc_gateway.ur import protocol
from hrc_gateway.ur.protocol import Ack, Frame

logger = logging.getLogger(__name__)

# The folder that holds hrc_gateway, so the worker imports it whatever the gateway's working directory.
_PROJECT_ROOT = Path(__file__).resolve().parents[2]
_STDERR_LINES_KEPT = 20
# A JSON line of state is ~2 KB; the default 64 KB limit is ample, this is a guard only.
_LINE_LIMIT = 1 << 20


class LinkError(Exception):
    """The RTDE connection could not be made or was lost. `in_use` when another RTDE client
    or a fieldbus adapter owns input registers the gateway needs."""

    def __init__(self, message: str, *, in_use: bool = False) -> None:
        super().__init__(message)
        self.in_use = in_use


class StepError(Exception):
    """A frames job that did not end in an acknowledgement.

    `reason` is "timeout", "cancelled", "busy", "io" or "lost"; `run_seq` is the number of
    the RUN frame when it was written (its acknowledgement may still come late).
    """

    def __init__(self, message: str, reason: str, run_seq: int | None = None) -> None:
        super().__init__(message)
        self.reason = reason
        self.run_seq = run_seq


@dataclass(frozen=True)
class RobotState:
    """One snapshot of what RTDEReceiveInterface reports (see rtde_worker.Worker.state)."""

    robot_mode: int
    safety_mode: int
    runtime_state: int
    speed_scaling: float
    target_speed_fraction: float
    actual_q: list[float]
    actual_qd: list[float]
    actual_current: list[float]
    actual_joint_voltage: list[float]
    actual_momentum: float
    actual_tcp_pose: list[float]
    actual_tcp_speed: list[float]
    actual_tcp_force: list[float]
    main_voltage: float
    robot_voltage: float
    robot_current: float
    out_ints: dict[int, int]
    out_doubles: dict[int, float]

    @classmethod
    def from_json(cls, data: dict[str, Any]) -> RobotState:
        fields = dict(data)
        fields["out_ints"] = dict(zip(protocol.OUTPUT_INTS, data["out_ints"], strict=True))
        fields["out_doubles"] = dict(zip(protocol.OUTPUT_DOUBLES, data["out_doubles"], strict=True))
        return cls(**fields)

    def ack(self) -> Ack:
        return Ack.from_outputs(self.out_ints, self.out_doubles)


OnState = Callable[[RobotState], Awaitable[None]]
OnLost = Callable[[str], Awaitable[None]]


class RTDELink:
    """One worker process, i.e. one RTDE connection; make a new link to reconnect."""

    def __init__(self, host: str, *, frequency: float, on_state: OnState, on_lost: OnLost) -> None:
        self.host = host
        self.frequency = frequency
        self._on_state = on_state
        self._on_lost = on_lost
        self._process: asyncio.subprocess.Process | None = None
        self._tasks: list[asyncio.Task[None]] = []
        self._replies: dict[int, asyncio.Future[dict[str, Any]]] = {}
        self._ids = itertools.count(1)
        self._ready: asyncio.Future[RobotState] | None = None
        self._stderr: collections.deque[str] = collections.deque(maxlen=_STDERR_LINES_KEPT)
        self.connected = False
        self._closing = False

    async def connect(self, timeout: float) -> RobotState:
        """Starts the worker and waits until it is connected; LinkError otherwise."""
        env = dict(os.environ)
        env["PYTHONPATH"] = os.pathsep.join(
            filter(None, [str(_PROJECT_ROOT), env.get("PYTHONPATH")])
        )
        self._process = await asyncio.create_subprocess_exec(
            sys.executable,
            "-m",
            "hrc_gateway.ur.rtde_worker",
            self.host,
            repr(self.frequency),
            stdin=asyncio.subprocess.PIPE,
            stdout=asyncio.subprocess.PIPE,
            stderr=asyncio.subprocess.PIPE,
            env=env,
            limit=_LINE_LIMIT,
        )
        self._ready = asyncio.get_running_loop().create_future()
        self._tasks = [
            asyncio.create_task(self._read_events(), name=f"rtde-events-{self.host}"),
            asyncio.create_task(self._read_stderr(), name=f"rtde-stderr-{self.host}"),
        ]
        try:
            state = await asyncio.wait_for(asyncio.shield(self._ready), timeout)
        except TimeoutError:
            await self.close()
            raise LinkError(
                f"The robot at {self.host}:30004 accepted no RTDE session within {timeout:g} s."
            ) from None
        except LinkError:
            await self.close()
            raise
        self.connected = True
        return state

    async def run_frames(self, frames: Sequence[Frame], timeout: float) -> Ack:
        """Sends the frames one after another; the acknowledgement of the last one."""
        request = {"op": "frames", "frames": [f.to_json() for f in frames], "timeout": timeout}
        # The worker enforces `timeout`; the extra second is for a worker that hangs.
        try:
            reply = await self._ask(request, timeout + 1.0)
        except LinkError as error:
            raise StepError(str(error), "lost") from None
        if not reply["ok"]:
            run_seq = reply.get("seq") if reply.get("run_sent") else None
            raise StepError(reply.get("message", reply["error"]), reply["error"], run_seq)
        a = reply["ack"]
        return Ack(a["seq"], a["outcome"], a["step"], (round(a["step_id"]), a["attempt"]))

    async def cancel_frames(self) -> None:
        await self._send({"op": "cancel"})

    async def set_speed_slider(self, fraction: float, timeout: float) -> None:
        reply = await self._ask({"op": "speed", "fraction": fraction}, timeout)
        if not reply["ok"]:
            raise LinkError("ur-rtde could not set the speed slider.")

    async def close(self) -> None:
        """Kills the worker (closing its sockets releases the registers); idempotent."""
        self._closing = True
        self.connected = False
        process, self._process = self._process, None
        if process is not None and process.returncode is None:
            with contextlib.suppress(ProcessLookupError):
                process.kill()
            with contextlib.suppress(TimeoutError):
                await asyncio.wait_for(process.wait(), 5.0)
        # close() may run inside one of these tasks (through on_lost); it must not await itself.
        others = [t for t in self._tasks if t is not asyncio.current_task()]
        for task in others:
            task.cancel()
        for task in others:
            with contextlib.suppress(asyncio.CancelledError):
                await task
        self._tasks = []
        if self._ready is not None and not self._ready.done():
            self._ready.cancel()
        self._fail_pending(LinkError("The RTDE connection was closed."))

    async def _ask(self, request: dict[str, Any], timeout: float) -> dict[str, Any]:
        if not self.connected:
            raise LinkError(f"There is no RTDE connection to {self.host}.")
        request_id = next(self._ids)
        future: asyncio.Future[dict[str, Any]] = asyncio.get_running_loop().create_future()
        self._replies[request_id] = future
        try:
            await self._send({**request, "id": request_id})
            return await asyncio.wait_for(future, timeout)
        except TimeoutError:
            await self._lose("The ur-rtde worker stopped answering; it was killed.")
            raise LinkError("The ur-rtde worker stopped answering.") from None
        finally:
            self._replies.pop(request_id, None)

    async def _send(self, request: dict[str, Any]) -> None:
        process = self._process
        if process is None or process.stdin is None:
            raise LinkError(f"There is no RTDE connection to {self.host}.")
        process.stdin.write((json.dumps(request) + "\n").encode())
        try:
            await asyncio.wait_for(process.stdin.drain(), 5.0)
        except (ConnectionError, TimeoutError):
            raise LinkError("The ur-rtde worker is gone.") from None

    async def _read_events(self) -> None:
        assert self._process is not None
        stdout = self._process.stdout
        assert stdout is not None
        while line := await stdout.readline():
            try:
                await self._dispatch(json.loads(line))
            except Exception:  # one bad event must not end the connection
                logger.exception("ur-rtde worker event %r from %s failed", line[:200], self.host)
        await self._lose(f"The ur-rtde worker exited.{self._stderr_tail()}")

    async def _dispatch(self, event: dict[str, Any]) -> None:
        kind = event["event"]
        if kind == "state":
            await self._on_state(RobotState.from_json(event["state"]))
        elif kind == "reply":
            future = self._replies.get(event["id"])
            if future is not None and not future.done():
                future.set_result(event)
        elif kind == "ready":
            if self._ready is not None and not self._ready.done():
                self._ready.set_result(RobotState.from_json(event["state"]))
        elif kind == "failed":
            message = event["message"]
            in_use = "already in use" in message
            if self._ready is not None and not self._ready.done():
                self._ready.set_exception(LinkError(message, in_use=in_use))
        elif kind == "lost":
            await self._lose(event["message"])

    async def _lose(self, message: str) -> None:
        if self._ready is not None and not self._ready.done():
            self._ready.set_exception(LinkError(message))
        was_connected = self.connected
        self.connected = False
        self._fail_pending(LinkError(message))
        if was_connected and not self._closing:
            self._closing = True
            logger.warning("RTDE connection to %s lost: %s", self.host, message)
            await self._on_lost(message)
            process = self._process
            if process is not None and process.returncode is None:
                with contextlib.suppress(ProcessLookupError):
                    process.kill()

    def _fail_pending(self, error: Exception) -> None:
        for future in self._replies.values():
            if not future.done():
                future.set_exception(error)

    async def _read_stderr(self) -> None:
        assert self._process is not None
        stderr = self._process.stderr
        assert stderr is not None
        while line := await stderr.readline():
            text = line.decode(errors="replace").rstrip()
            if text:
                self._stderr.append(text)
                logger.debug("ur-rtde worker %s: %s", self.host, text)

    def _stderr_tail(self) -> str:
        return f" It said: {' | '.join(self._stderr)}" if self._stderr else ""
