"""`manage.py run_pattern` stopped with SIGTERM (a test's timeout, a supervisor) stops the gateway
processes it started, instead of leaving simulated cobots serving after it is gone."""

from __future__ import annotations

import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

from tests.cases.test_run_pattern_embedded import ROOT, embedded_environment


def gateways_of(pid: int) -> list[int]:
    """The live cobot gateways whose parent is `pid` (not its engine workers), from /proc."""
    return [
        child
        for child in children_of(pid)
        if b"cobot_gateway" in Path(f"/proc/{child}/cmdline").read_bytes()
    ]


def children_of(pid: int) -> list[int]:
    """The live processes whose parent is `pid`, read from /proc."""
    found = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            # The command name (field 2) may hold spaces; the fields after ')' are fixed.
            state, parent = stat.read_text().rsplit(")", 1)[1].split()[:2]
        except (OSError, IndexError):
            continue  # ended while we read
        if int(parent) == pid and state != "Z":
            found.append(int(stat.parent.name))
    return found


def wait_until_serving(pid: int, run: subprocess.Popen[str], deadline: float) -> None:
    """Waits until the gateway `pid` accepts connections on the port its command line names."""
    arguments = Path(f"/proc/{pid}/cmdline").read_bytes().split(b"\0")
    port = int(arguments[arguments.index(b"--port") + 1])
    while time.monotonic() < deadline:
        assert run.poll() is None, run.stderr.read() if run.stderr else ""
        with socket.socket() as probe:
            if probe.connect_ex(("127.0.0.1", port)) == 0:
                return
        time.sleep(0.1)
    raise AssertionError(f"the gateway {pid} is not serving on {port}")


def test_sigterm_stops_the_gateways_run_pattern_started(tmp_path: Path) -> None:
    pattern = ROOT / "hrc" / "patterns" / "examples" / "coop_1o1c_polishing.json"
    command = [
        sys.executable, "manage.py", "run_pattern", str(pattern), "--simulate", "--json",
        "--cases", "3", "--time-scale", "1",  # real time: still running when stopped
    ]  # fmt: skip
    run = subprocess.Popen(
        command, cwd=ROOT, env=embedded_environment(tmp_path),
        stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
    )  # fmt: skip
    gateways: list[int] = []
    try:
        deadline = time.monotonic() + 60
        while not (gateways := gateways_of(run.pid)) and time.monotonic() < deadline:
            assert run.poll() is None, run.stderr.read() if run.stderr else ""
            time.sleep(0.1)
        assert gateways, "run_pattern started no gateway within 60 s"
        for pid in gateways:  # serving, so the simulation owns it (not mid-start)
            wait_until_serving(pid, run, deadline)

        run.send_signal(signal.SIGTERM)
        _, stderr = run.communicate(timeout=30)

        assert run.returncode == 128 + signal.SIGTERM
        assert "Traceback" not in stderr, stderr
        alive = [pid for pid in gateways if Path(f"/proc/{pid}").exists()]
        assert alive == [], "gateways left running after run_pattern ended"
    finally:
        if run.poll() is None:
            run.kill()
            run.wait()
        for pid in gateways:  # left only when the test failed: leave nothing behind
            if Path(f"/proc/{pid}").exists():
                os.kill(pid, signal.SIGKILL)
