"""The processes of a running demo, started in order and stopped together.

Each child gets a session (process group) of its own, so Ctrl-C at the
terminal reaches only the runner, which then stops the children itself: the
web server first, the gateways last, each with SIGTERM to its whole group
(a Celery worker's pool children included) and SIGKILL after a grace
period. On Linux each child is also killed with the runner
(PR_SET_PDEATHSIG), so a runner killed outright leaves no orphans either.
"""

from __future__ import annotations

import contextlib
import ctypes
import os
import signal
import socket
import subprocess
import sys
import time
import urllib.request
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from hrc.demo.organisation import DEMO_COBOTS

ROOT = Path(__file__).resolve().parents[2]
MANAGE = str(ROOT / "manage.py")
GRACE_SECONDS = 10.0
_PR_SET_PDEATHSIG = 1


class DemoFailed(Exception):
    """A process of the demo could not start, or stopped by itself; the message says which and why."""


@dataclass(frozen=True)
class Plan:
    """What to run: where the web server listens, the gateways' ports, with or without Redis."""

    address: str = "127.0.0.1"
    port: int = 8000
    cobot_ports: Mapping[str, int] = field(
        default_factory=lambda: {cobot.name: cobot.port for cobot in DEMO_COBOTS}
    )
    time_scale: float = 1.0
    redis: bool = False
    logs: Path = ROOT / "var" / "demo"

    @property
    def url(self) -> str:
        host = f"[{self.address}]" if ":" in self.address else self.address
        return f"http://{host}:{self.port}"

    @property
    def worker_slots(self) -> int:
        """Two Celery processes per cobot, for its step (held while it runs) and for the pause
        or resume a space constraint sends it meanwhile, and one for device calls."""
        return 2 * len(self.cobot_ports) + 1

    def children(self) -> list[Child]:
        """The processes in start order: gateways, then (with Redis) worker and monitor, then web."""
        python = sys.executable
        gateways = [self._gateway(name, port) for name, port in self.cobot_ports.items()]
        background = []
        if self.redis:
            background = [
                Child(
                    "worker",
                    [python, "-m", "celery", "-A", "hrc", "worker", "--beat",
                     "--schedule", str(self.logs / "celerybeat-schedule"),
                     "--hostname", "demo@%h", "--concurrency", str(self.worker_slots),
                     "--loglevel", "INFO"],
                    self.logs, ready_text=" ready.",
                ),
                Child(
                    "monitor", [python, MANAGE, "live_cobots"], self.logs,
                    ready_text="live monitor watching",
                ),
            ]  # fmt: skip
        # --insecure: the frontend's bundles are served even when DEBUG is off.
        web = Child(
            "web",
            [python, MANAGE, "runserver", "--noreload", "--insecure", f"{self.address}:{self.port}"],
            self.logs, ready_url=f"{self.url}/accounts/login/",
        )  # fmt: skip
        return [*gateways, *background, web]

    def _gateway(self, name: str, port: int) -> Child:
        argv = [
            sys.executable, MANAGE, "cobot_gateway", "--name", name, "--port", str(port),
            "--backend", "sim", "--insecure", "--time-scale", str(self.time_scale),
        ]  # fmt: skip
        return Child(f"gateway-{name}", argv, self.logs, ready_text="gateway serving")

    def taken_ports(self) -> list[str]:
        """'address:port' of each port the plan needs that something else holds."""
        wanted = [(self.address, self.port)]
        wanted += [("127.0.0.1", port) for port in self.cobot_ports.values()]
        return [f"{host}:{port}" for host, port in wanted if not _free(host, port)]


@dataclass
class Child:
    """One process of the demo; its output goes to <logs>/<name>.log."""

    name: str
    argv: list[str]
    logs: Path
    ready_text: str | None = None
    ready_url: str | None = None
    process: subprocess.Popen[bytes] | None = None

    @property
    def log(self) -> Path:
        return self.logs / f"{self.name}.log"

    def start(self, environment: Mapping[str, str]) -> None:
        self.logs.mkdir(parents=True, exist_ok=True)
        with self.log.open("wb") as log:
            self.process = subprocess.Popen(
                self.argv, cwd=ROOT, stdin=subprocess.DEVNULL, stdout=log,
                stderr=subprocess.STDOUT, env={**environment, "PYTHONUNBUFFERED": "1"},
                start_new_session=True, preexec_fn=_die_with_parent,
            )  # fmt: skip

    def is_ready(self) -> bool:
        if self.ready_text is not None and self.ready_text not in self.output():
            return False
        if self.ready_url is not None:
            try:
                urllib.request.urlopen(self.ready_url, timeout=2).close()
            except OSError:
                return False
        return True

    def exit_code(self) -> int | None:
        """None while it runs."""
        return None if self.process is None else self.process.poll()

    def output(self) -> str:
        try:
            return self.log.read_text(errors="replace")
        except FileNotFoundError:
            return ""

    def tail(self, lines: int = 20) -> str:
        return "\n".join(self.output().splitlines()[-lines:])

    def stop(self, grace: float = GRACE_SECONDS) -> None:
        """SIGTERM to the child's whole group; SIGKILL to what is left after `grace` seconds."""
        if self.process is None:
            return
        group = self.process.pid  # its own session: the group id is its pid
        with contextlib.suppress(ProcessLookupError):
            os.killpg(group, signal.SIGTERM)
        with contextlib.suppress(subprocess.TimeoutExpired):
            self.process.wait(grace)
        # The leader may be gone while its children (a worker's pool) linger.
        with contextlib.suppress(ProcessLookupError):
            os.killpg(group, signal.SIGKILL)
        self.process.wait()


class Demo:
    """Starts a plan's children, watches them, and stops them all."""

    def __init__(self, plan: Plan, environment: Mapping[str, str] | None = None) -> None:
        self.plan = plan
        self.environment = dict(os.environ if environment is None else environment)
        self.children = plan.children()

    def start(self, progress: Callable[[str], None], timeout: float = 120.0) -> None:
        """Starts every child, each group once the previous is ready; raises DemoFailed."""
        gateways = [c for c in self.children if c.name.startswith("gateway-")]
        rest = [c for c in self.children if c not in gateways]
        for group in (gateways, *[[child] for child in rest]):
            for child in group:
                progress(f"starting {child.name} (log: {_shown(child.log)})")
                child.start(self.environment)
            self._wait_ready(group, timeout)

    def _wait_ready(self, children: Sequence[Child], timeout: float) -> None:
        deadline = time.monotonic() + timeout
        waiting = list(children)
        while waiting:
            for child in list(waiting):
                if child.exit_code() is not None:
                    raise DemoFailed(_ended(child))
                if child.is_ready():
                    waiting.remove(child)
            if waiting and time.monotonic() > deadline:
                names = ", ".join(child.name for child in waiting)
                raise DemoFailed(f"{names} did not start within {timeout:.0f} s.")
            time.sleep(0.1)

    def serve(self, stop: Callable[[], bool]) -> None:
        """Returns when `stop()` is true; raises DemoFailed when a child ends by itself."""
        while not stop():
            for child in self.children:
                if child.exit_code() is not None:
                    raise DemoFailed(_ended(child))
            time.sleep(0.2)

    def stop(self) -> None:
        """Stops every child that was started, the last started first."""
        for child in reversed(self.children):
            child.stop()

    def pids(self) -> list[int]:
        return [c.process.pid for c in self.children if c.process is not None]


def _ended(child: Child) -> str:
    return f"{child.name} stopped (exit code {child.exit_code()}); the end of {_shown(child.log)}:\n{child.tail()}"


def _shown(path: Path) -> str:
    with contextlib.suppress(ValueError):
        return str(path.relative_to(ROOT))
    return str(path)


def _free(host: str, port: int) -> bool:
    family = socket.AF_INET6 if ":" in host else socket.AF_INET
    with socket.socket(family) as probe:
        # As servers bind: a port in TIME_WAIT from a demo just stopped is free.
        probe.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            probe.bind((host, port))
        except OSError:
            return False
    return True


def _die_with_parent() -> None:
    """In the child before exec: SIGKILL when the runner dies (Linux; elsewhere a no-op).

    SIGKILL, not SIGTERM: with a case's step in flight a gateway and the web
    server that all get SIGTERM at once wait on each other's goodbye, and a
    dead runner cannot follow up with SIGKILL as its own stop does. Every
    simulator change is saved as it happens, and a job cut short is taken
    back by the sweeper on the next start.
    """
    if sys.platform.startswith("linux"):
        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(_PR_SET_PDEATHSIG, signal.SIGKILL)
