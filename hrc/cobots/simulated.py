"""Simulated cobot gateways as child processes, for `run_pattern --simulate`, the tests and the benchmark.

A gateway runs as its own process (`manage.py cobot_gateway`), as in a
plant, so a test can kill it mid-step (SIGKILL) and start it again on the
same port with the same simulator state file, as a gateway host restarts.
"""

from __future__ import annotations

import os
import random
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path
from typing import Self

_ROOT = Path(__file__).resolve().parents[2]
# Simulated time runs this many times faster than real time (twenty times).
TIME_SCALE = 0.05


# Servers started here listen on a port drawn from this range, below the kernel's ephemeral
# ports (32768 and up on Linux): a port the kernel hands out for port 0 may be taken by any
# outgoing connection between the probe and the server's bind, or while a gateway restarts.
_PORTS = range(20000, 32768)
# Not the `random` module's shared generator: a test that seeds it would make parallel test
# processes draw the same ports.
_DRAW = random.SystemRandom()
# The ports this process has handed out: each goes to a server that may not have bound it yet
# (the gateways of one run are given theirs before any starts), so none is handed out twice.
_GIVEN: set[int] = set()


def free_port() -> int:
    """A TCP port free on 127.0.0.1 right now (closed again, bound later by a server), never
    one this process has handed out before."""
    for _ in range(200):
        port = _DRAW.choice(_PORTS)
        if port in _GIVEN:
            continue
        with socket.socket() as probe:
            try:
                probe.bind(("127.0.0.1", port))
            except OSError:
                continue
        _GIVEN.add(port)
        return port
    raise OSError(f"no free port on 127.0.0.1 in {_PORTS.start}-{_PORTS.stop - 1}")


class GatewayProcess:
    """`manage.py cobot_gateway` for one simulated cobot; `start()`, `kill()`, `start()` again."""

    def __init__(
        self,
        name: str,
        state_file: Path,
        *,
        time_scale: float = TIME_SCALE,
        extra: tuple[str, ...] = ("--insecure",),
    ) -> None:
        self.name = name
        self.port = free_port()
        self.state_file = state_file
        self.time_scale = time_scale
        self.extra = extra
        self.process: subprocess.Popen[bytes] | None = None
        # The gateway's output goes to a file: a pipe nobody reads would block it when full.
        self.log = state_file.with_suffix(".log")

    @property
    def endpoint(self) -> str:
        return f"opc.tcp://127.0.0.1:{self.port}"

    def start(self, timeout: float = 30.0) -> Self:
        """Starts the gateway and returns once it says it is serving."""
        command = [
            sys.executable,
            str(_ROOT / "manage.py"),
            "cobot_gateway",
            "--name",
            self.name,
            "--port",
            str(self.port),
            "--backend",
            "sim",
            "--time-scale",
            str(self.time_scale),
            "--state-file",
            str(self.state_file),
            "--seed",
            "1",
            *self.extra,
        ]
        offset = self.log.stat().st_size if self.log.exists() else 0
        with self.log.open("ab") as log:
            self.process = subprocess.Popen(
                command,
                cwd=_ROOT,
                stdout=log,
                stderr=subprocess.STDOUT,
                env={**os.environ, "PYTHONUNBUFFERED": "1"},
            )
        deadline = time.monotonic() + timeout
        try:
            while time.monotonic() < deadline and self.process.poll() is None:
                if "gateway serving" in self.output(offset):
                    return self
                time.sleep(0.02)
        except BaseException:
            self.kill()  # stopped while it starts (Ctrl-C, SIGTERM): not left serving alone
            raise
        output = self.output(offset)
        self.kill()
        raise RuntimeError(f"The gateway did not start:\n{output}")

    def output(self, offset: int = 0) -> str:
        """What the gateway printed (from byte `offset` of its log)."""
        with self.log.open("rb") as log:
            log.seek(offset)
            return log.read().decode(errors="replace")

    def kill(self) -> None:
        """SIGKILL: no clean shutdown, as when a host loses power."""
        if self.process is not None and self.process.poll() is None:
            self.process.send_signal(signal.SIGKILL)
            self.process.wait(10)
        self.process = None

    def stop(self) -> None:
        """SIGTERM: the clean shutdown."""
        if self.process is not None and self.process.poll() is None:
            self.process.terminate()
            try:
                self.process.wait(10)
            except subprocess.TimeoutExpired:
                self.kill()
        self.process = None
