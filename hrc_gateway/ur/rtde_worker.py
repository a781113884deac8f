"""The ur-rtde worker: a child process that owns one cobot's RTDE connection.

Started by link.RTDELink as `python -m hrc_gateway.ur.rtde_worker HOST FREQUENCY`;
one process lives as long as one connection: it exits when the connection is
lost, and the gateway starts a new one to reconnect.

Why a process and not a thread: the constructors of ur-rtde 1.6.5's
RTDEReceiveInterface and RTDEIOInterface hold the GIL while they block on the
network (their pybind11 bindings release it for method calls, not for
`__init__`), and RTDE::receive has no deadline. A controller that accepts the
connection but does not answer would freeze every thread of the process that
constructs them, the OPC UA server included. In a child, the gateway stays
responsive and kills the child when a deadline passes.

Protocol, one JSON object per line. Requests on stdin:
  {"op": "frames", "id": n, "frames": [Frame.to_json()...], "timeout": s}
  {"op": "cancel"}                       abandons the frames job in progress
  {"op": "speed", "id": n, "fraction": f}
Events on stdout:
  {"event": "ready", "state": {...}}     connected; the frame registers are reset
  {"event": "failed", "message": str}    could not connect; the process exits
  {"event": "state", "state": {...}}     every STATE_PERIOD
  {"event": "reply", "id": n, "ok": true, ...} or {..., "ok": false, "error": str, "message": str}
  {"event": "lost", "message": str}      the connection dropped; the process exits
"""

from __future__ import annotations

import json
import os
import queue
import sys
import threading
import time
from dataclasses import dataclass
from typing import IO, Any

# Importing ur-rtde prints nothing; what its interfaces print once constructed goes to
# stderr, because main() redirects stdout first.
import rtde_io
import rtde_receive

from hrc_gateway import urua
from hrc_gateway.ur import protocol
from hrc_gateway.ur.protocol import Frame

STATE_PERIOD = 0.02  # state snapshots at ~50 Hz
ACK_POLL = 0.001  # while a frame waits for its acknowledgement (RTDE delivers every 2 ms)

EXIT_FAILED = 2
EXIT_LOST = 3


@dataclass
class FramesJob:
    """Frames being sent, one at a time, each after the previous one was acknowledged."""

    request_id: int
    frames: list[Frame]
    deadline: float
    index: int = 0
    seq: int | None = None  # of the frame written and not yet acknowledged

    @property
    def run_sent(self) -> bool:
        return self.seq is not None and self.frames[self.index].kind == protocol.KIND_RUN


class Worker:
    def __init__(self, receive: Any, io: Any, out: IO[str]) -> None:
        self.receive = receive
        self.io = io
        self.out = out
        self.seq = 0
        self.job: FramesJob | None = None

    def emit(self, message: dict[str, Any]) -> None:
        self.out.write(json.dumps(message) + "\n")

    def reset_frames(self) -> None:
        """Writes a NOOP frame numbered 0, so the first real frame (1) is a change for the
        program whatever a previous gateway left in input int 42."""
        self.io.setInputIntRegister(protocol.IN_KIND, protocol.KIND_NOOP)
        self.io.setInputIntRegister(protocol.IN_SEQ, 0)
        self.seq = 0

    def state(self) -> dict[str, Any]:
        r = self.receive
        return {
            "robot_mode": r.getRobotMode(),
            "safety_mode": r.getSafetyMode(),
            "runtime_state": r.getRuntimeState(),
            "speed_scaling": r.getSpeedScaling(),
            "target_speed_fraction": r.getTargetSpeedFraction(),
            "actual_q": r.getActualQ(),
            "actual_qd": r.getActualQd(),
            "actual_current": r.getActualCurrent(),
            "actual_joint_voltage": r.getActualJointVoltage(),
            "actual_momentum": r.getActualMomentum(),
            "actual_tcp_pose": r.getActualTCPPose(),
            "actual_tcp_speed": r.getActualTCPSpeed(),
            "actual_tcp_force": r.getActualTCPForce(),
            "main_voltage": r.getActualMainVoltage(),
            "robot_voltage": r.getActualRobotVoltage(),
            "robot_current": r.getActualRobotCurrent(),
            "out_ints": [r.getOutputIntRegister(n) for n in protocol.OUTPUT_INTS],
            "out_doubles": [r.getOutputDoubleRegister(n) for n in protocol.OUTPUT_DOUBLES],
        }

    def handle(self, request: dict[str, Any]) -> None:
        op = request.get("op")
        if op == "frames":
            self._start_frames(request)
        elif op == "cancel":
            if self.job is not None:
                self._finish_job(ok=False, error="cancelled", message="Cancelled by the gateway.")
        elif op == "speed":
            ok = bool(self.io.setSpeedSlider(float(request["fraction"])))
            self.emit({"event": "reply", "id": request["id"], "ok": ok, "error": "io"})
        else:
            self.emit({"event": "reply", "id": request.get("id"), "ok": False, "error": "op"})

    def _start_frames(self, request: dict[str, Any]) -> None:
        if self.job is not None:
            message = "Another step is still being sent."
            self.emit(
                {
                    "event": "reply",
                    "id": request["id"],
                    "ok": False,
                    "error": "busy",
                    "message": message,
                }
            )
            return
        frames = [Frame.from_json(f) for f in request["frames"]]
        deadline = time.monotonic() + float(request["timeout"])
        self.job = FramesJob(request["id"], frames, deadline)

    def advance(self, now: float) -> None:
        """Writes the next frame, or checks the acknowledgement of the one written."""
        job = self.job
        assert job is not None
        if job.seq is None:
            self._write(job.frames[job.index], job)
        elif self.receive.getOutputIntRegister(protocol.OUT_ACK) == job.seq:
            if job.index == len(job.frames) - 1:
                self._finish_job(ok=True)
                return
            job.index += 1
            self._write(job.frames[job.index], job)
        elif now > job.deadline:
            kind = "RUN" if job.frames[job.index].kind == protocol.KIND_RUN else "DATA"
            message = f"No acknowledgement of {kind} frame {job.seq} in time."
            self._finish_job(ok=False, error="timeout", message=message)

    def _write(self, frame: Frame, job: FramesJob) -> None:
        # Sequence numbers only need to change from one frame to the next.
        self.seq = self.seq + 1 if self.seq < urua.INT32_MAX else 1
        writes: list[tuple[Any, int, float]] = [
            (self.io.setInputIntRegister, protocol.IN_KIND, frame.kind),
            *((self.io.setInputIntRegister, reg, value) for reg, value in frame.ints),
            *((self.io.setInputDoubleRegister, reg, value) for reg, value in frame.doubles),
            (self.io.setInputIntRegister, protocol.IN_SEQ, self.seq),  # last
        ]
        for setter, register, value in writes:
            if not setter(register, value):
                message = f"ur-rtde could not write input register {register}."
                self._finish_job(ok=False, error="io", message=message)
                return
        job.seq = self.seq

    def _finish_job(self, *, ok: bool, error: str = "", message: str = "") -> None:
        job = self.job
        assert job is not None
        self.job = None
        reply: dict[str, Any] = {"event": "reply", "id": job.request_id, "ok": ok}
        if ok:
            r = self.receive
            reply["ack"] = {
                "seq": job.seq,
                "outcome": r.getOutputIntRegister(protocol.OUT_OUTCOME),
                "attempt": r.getOutputIntRegister(protocol.OUT_ATTEMPT),
                "step": r.getOutputIntRegister(protocol.OUT_STEP),
                "step_id": r.getOutputDoubleRegister(protocol.OUT_STEP_ID),
            }
        else:
            reply |= {"error": error, "message": message, "seq": job.seq, "run_sent": job.run_sent}
        self.emit(reply)

    def serve(self, requests: queue.Queue[dict[str, Any] | None]) -> int:
        try:
            return self._serve(requests)
        except (
            RuntimeError
        ) as error:  # ur-rtde gave up on the connection (its own reconnect failed)
            self.emit({"event": "lost", "message": f"ur-rtde: {error}"})
            return EXIT_LOST

    def _serve(self, requests: queue.Queue[dict[str, Any] | None]) -> int:
        next_state = time.monotonic()
        while True:
            now = time.monotonic()
            if not self.receive.isConnected():
                self.emit({"event": "lost", "message": "The robot closed the RTDE connection."})
                return EXIT_LOST
            if self.job is not None:
                self.advance(now)
            if now >= next_state:
                self.emit({"event": "state", "state": self.state()})
                next_state = now + STATE_PERIOD
            wait = ACK_POLL if self.job is not None else max(0.0, next_state - time.monotonic())
            try:
                request = requests.get(timeout=wait)
            except queue.Empty:
                continue
            if request is None:  # the gateway closed our stdin
                return 0
            self.handle(request)


def _protocol_stream() -> IO[str]:
    # ur-rtde prints diagnostics on stdout (std::cout). It keeps fd 1, now pointing at
    # stderr; the protocol goes to a private copy of the original stdout.
    sys.stdout.flush()
    fd = os.dup(1)
    os.dup2(2, 1)
    return os.fdopen(fd, "w", buffering=1)


def _read_requests(requests: queue.Queue[dict[str, Any] | None]) -> None:
    for line in sys.stdin:
        if line.strip():
            requests.put(json.loads(line))
    requests.put(None)


def main(argv: list[str]) -> int:
    host, frequency = argv[1], float(argv[2])
    out = _protocol_stream()
    try:
        receive = rtde_receive.RTDEReceiveInterface(
            host, frequency=frequency, use_upper_range_registers=True
        )
        io = rtde_io.RTDEIOInterface(host, use_upper_range_registers=True)
        worker = Worker(receive, io, out)
        worker.reset_frames()
    except RuntimeError as error:
        out.write(json.dumps({"event": "failed", "message": str(error)}) + "\n")
        return EXIT_FAILED
    worker.emit({"event": "ready", "state": worker.state()})
    requests: queue.Queue[dict[str, Any] | None] = queue.Queue()
    threading.Thread(target=_read_requests, args=(requests,), daemon=True).start()
    return worker.serve(requests)


if __name__ == "__main__":
    # os._exit skips ur-rtde's destructors, which pause the stream and sleep 500 ms;
    # closing the sockets is all the controller needs to release the registers.
    try:
        code = main(sys.argv)
    except BrokenPipeError:  # the gateway went away
        code = 0
    sys.stderr.flush()
    os._exit(code)
