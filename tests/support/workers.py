"""Real Celery worker processes and a private Redis, for the tests and the benchmark.

A `WorkerProcess` is `celery -A hrc worker` (optionally with the beat that
runs the sweeper) in its own process group, so SIGKILL takes the whole
worker down as a power cut would. A `RedisProcess` is a throw-away
redis-server on a free loopback port, so a run can restart its broker
without touching anyone else's.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from collections.abc import Mapping
from pathlib import Path
from typing import Self

import redis

from hrc.cobots.simulated import free_port
from tests.support.paths import ROOT


def process_group(leader: int) -> set[int]:
    """The processes of the group `leader` leads (a worker started in a session of its own)."""
    found = subprocess.run(
        ["pgrep", "-g", str(leader)], capture_output=True, text=True, check=False
    )
    return {int(pid) for pid in found.stdout.split()}


class RedisProcess:
    """redis-server on 127.0.0.1 with no persistence; `restart()` keeps the port (and loses the queue)."""

    def __init__(self, workdir: Path) -> None:
        self.port = free_port()
        self.workdir = workdir
        self.process: subprocess.Popen[bytes] | None = None

    @property
    def url(self) -> str:
        return f"redis://127.0.0.1:{self.port}/0"

    def start(self, timeout: float = 10.0) -> Self:
        self.process = subprocess.Popen(
            ["redis-server", "--bind", "127.0.0.1", "--port", str(self.port),
             "--save", "", "--appendonly", "no", "--dir", str(self.workdir)],
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
        )  # fmt: skip
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            try:
                redis.Redis.from_url(self.url).ping()
                return self
            except redis.ConnectionError:
                time.sleep(0.05)
        raise RuntimeError(f"redis-server did not start on port {self.port}")

    def stop(self) -> None:
        if self.process is not None and self.process.poll() is None:
            self.process.kill()
            self.process.wait(10)
        self.process = None

    def restart(self, down_for: float = 1.0) -> None:
        self.stop()
        time.sleep(down_for)
        self.start()


class WorkerProcess:
    """One Celery worker (prefork, `concurrency` children) against a database and a broker."""

    def __init__(
        self,
        workdir: Path,
        *,
        name: str,
        environment: Mapping[str, str],
        beat: bool = False,
        concurrency: int = 1,
    ) -> None:
        self.workdir = workdir
        self.name = name
        self.environment = dict(environment)
        self.beat = beat
        self.concurrency = concurrency
        self.log = workdir / f"{name}.log"
        self.process: subprocess.Popen[bytes] | None = None

    def start(self, timeout: float = 60.0) -> Self:
        command = [
            sys.executable, "-m", "celery", "-A", "hrc", "worker",
            "--hostname", f"{self.name}@%h", "--pool", "prefork",
            "--concurrency", str(self.concurrency), "--loglevel", "INFO",
            "--without-gossip", "--without-mingle", "--without-heartbeat",
        ]  # fmt: skip
        if self.beat:
            command += ["--beat", "--schedule", str(self.workdir / f"{self.name}-beat")]
        offset = self.log.stat().st_size if self.log.exists() else 0
        with self.log.open("ab") as log:
            self.process = subprocess.Popen(
                command, cwd=ROOT, stdout=log, stderr=subprocess.STDOUT,
                env={**os.environ, **self.environment, "PYTHONUNBUFFERED": "1"},
                start_new_session=True,  # its own process group: kill() takes the children too
            )  # fmt: skip
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline and self.process.poll() is None:
            if " ready." in self.output(offset):
                return self
            time.sleep(0.05)
        output = self.output(offset)
        self.kill()
        raise RuntimeError(f"The Celery worker did not start:\n{output[-4000:]}")

    def output(self, offset: int = 0) -> str:
        with self.log.open("rb") as log:
            log.seek(offset)
            return log.read().decode(errors="replace")

    def pids(self) -> set[int]:
        """The worker's main process and its pool children."""
        return process_group(self.process.pid) if self.process is not None else set()

    def kill(self) -> None:
        """SIGKILL to the whole worker, children included: no goodbye, no acknowledgement."""
        if self.process is not None and self.process.poll() is None:
            os.killpg(self.process.pid, signal.SIGKILL)
            self.process.wait(10)
        self.process = None

    def stop(self) -> None:
        if self.process is not None and self.process.poll() is None:
            os.killpg(self.process.pid, signal.SIGTERM)
            try:
                self.process.wait(20)
            except subprocess.TimeoutExpired:
                self.kill()
        self.process = None
