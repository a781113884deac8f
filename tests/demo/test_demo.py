"""`manage.py demo` (what `make demo` runs), started as a person starts it and stopped with Ctrl-C.

On embedded defaults (SQLite, no Redis) and on DATABASE_URL and REDIS_URL
(a scratch PostgreSQL database, a private redis-server): the printed
passwords sign each persona in, their pages answer, both simulated cobots
reach the tablets (through the monitor inside the server, or the monitor
process and Redis), and after SIGINT or SIGTERM no process it started is
left and its ports are free.
"""

from __future__ import annotations

import asyncio
import json
import os
import re
import signal
import socket
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest
from websockets.asyncio.client import connect

from hrc.cobots.drivers.runner import driver_for
from hrc.cobots.simulated import free_port
from hrc.demo.management.commands.demo import PREPARED
from hrc.demo.organisation import PERSONAS
from hrc.demo.plant import STARTED_CASES
from hrc_gateway import urua
from tests.demo.rig import Browserless, DemoRun, alive, scratch_postgres
from tests.support.paths import ROOT
from tests.support.polling import until
from tests.support.workers import RedisProcess

CONFIG = re.compile(r'<script id="tablet-config" type="application/json">(.*?)</script>', re.S)


@pytest.fixture
def redis_url(tmp_path: Path) -> Iterator[str]:
    server = RedisProcess(tmp_path).start()
    yield server.url
    server.stop()


def test_on_embedded_defaults_it_serves_every_persona_and_ctrl_c_ends_every_process(
    tmp_path: Path,
) -> None:
    demo = DemoRun(tmp_path, database_url=f"sqlite:///{tmp_path / 'demo.sqlite3'}").start()
    try:
        assert "SQLite" in demo.output()
        assert "embedded mode" in demo.output()
        assert f"cobot1, cobot2: {PREPARED}" in demo.output()
        assert _cobot_states(demo) == {"cobot1": RUNNING_NORMAL, "cobot2": RUNNING_NORMAL}
        started = demo.started_cases()
        assert set(started) == {pattern for pattern, _ in STARTED_CASES}
        for case in started.values():
            assert f"{demo.url}/cases/{case}/" in demo.output()
        _check_personas(demo)
        # The monitor runs inside the web server: its states reach a tablet over the in-memory layer.
        assert asyncio.run(_reachable_cobots(demo, "operator1")) == {"cobot1", "cobot2"}
        children = demo.descendants()
        commands = list(children.values())
        assert sum("cobot_gateway" in command for command in commands) == 2
        assert sum("runserver" in command for command in commands) == 1
        assert not any("celery" in command or "live_cobots" in command for command in commands)
        assert demo.signal(signal.SIGINT) == 0
    finally:
        demo.stop()
    _check_everything_ended(demo, children)
    assert "every process the demo started has ended" in demo.output()
    _check_passwords_only_printed(demo)


def test_with_database_and_redis_urls_it_runs_a_worker_and_the_monitor_and_sigterm_ends_them(
    tmp_path: Path, redis_url: str
) -> None:
    with scratch_postgres(f"hrc_demo_{os.getpid()}") as database_url:
        demo = DemoRun(
            tmp_path, database_url=database_url, redis_url=redis_url, arguments=["--no-cases"]
        ).start()
        try:
            assert "PostgreSQL hrc_demo_" in demo.output()
            assert "a Celery worker with beat" in demo.output()
            assert f"cobot1, cobot2: {PREPARED}" in demo.output()
            assert _cobot_states(demo) == {"cobot1": RUNNING_NORMAL, "cobot2": RUNNING_NORMAL}
            assert "Cases: none started (--no-cases)" in demo.output()
            assert demo.started_cases() == {}
            engineer = Browserless(demo.url)
            assert engineer.sign_in("engineer", demo.passwords()["engineer"])
            status, _, body = engineer.get("/api/cases/")
            assert (status, json.loads(body)["count"]) == (200, 0)
            _check_personas(demo)
            assert asyncio.run(_reachable_cobots(demo, "operator2")) == {"cobot1", "cobot2"}
            children = demo.descendants()
            commands = list(children.values())
            # The worker, its pool (two slots per cobot, for its step and a pause meanwhile,
            # and one for device calls) and the beat.
            assert sum("celery -A hrc worker --beat" in command for command in commands) >= 6
            assert any("--concurrency 5" in command for command in commands)
            assert sum("live_cobots" in command for command in commands) == 1
            assert sum("cobot_gateway" in command for command in commands) == 2
            assert " ready." in (demo.logs / "worker.log").read_text()
            assert demo.signal(signal.SIGTERM) == 0
        finally:
            demo.stop()
    _check_everything_ended(demo, children)


def test_a_cobot_left_in_a_protective_stop_is_named_with_what_to_do_and_stays_stopped(
    tmp_path: Path,
) -> None:
    """An earlier run's protective stop is saved in the simulator's state: the software keeps it."""
    database_url = f"sqlite:///{tmp_path / 'demo.sqlite3'}"
    earlier = DemoRun(tmp_path, database_url=database_url, arguments=["--no-cases"]).start()
    try:
        fault = subprocess.run(
            [sys.executable, "manage.py", "cobot_fault", "cobot1", "protective-stop",
             "--endpoint", f"opc.tcp://127.0.0.1:{earlier.cobot_ports['cobot1']}"],
            cwd=ROOT, env=earlier.environment, capture_output=True, text=True, timeout=60,
        )  # fmt: skip
        assert fault.returncode == 0, fault.stderr
        assert earlier.signal(signal.SIGINT) == 0
    finally:
        earlier.stop()

    demo = DemoRun(tmp_path, database_url=database_url).start()
    try:
        output = demo.output()
        assert f"cobot2: {PREPARED}" in output
        assert f"cobot1, cobot2: {PREPARED}" not in output
        named = re.search(r"^cobot1: not prepared: (.*)$", output, re.MULTILINE)
        assert named is not None, output
        assert "PROTECTIVE_STOP" in named.group(1)
        assert named.group(1).startswith("PowerOn refused")
        assert "cobot_fault cobot1 unlock" in named.group(1)
        assert "cobot_call cobot1 PowerOn" in named.group(1)
        # Nothing cleared the stop or powered the arm on; the demo serves all the same.
        states = _cobot_states(demo)
        assert states["cobot1"][1] == "SAFETY_MODE_PROTECTIVE_STOP"
        assert states["cobot2"] == RUNNING_NORMAL
        assert Browserless(demo.url).sign_in("operator1", demo.passwords()["operator1"])
        assert demo.signal(signal.SIGINT) == 0
    finally:
        demo.stop()


def test_a_demo_killed_outright_takes_its_processes_with_it(tmp_path: Path) -> None:
    """SIGKILL leaves the runner no chance to stop anything: the children go by PR_SET_PDEATHSIG."""
    demo = DemoRun(tmp_path, database_url=f"sqlite:///{tmp_path / 'demo.sqlite3'}").start()
    try:
        children = demo.descendants()
        assert len(children) >= 3
        assert demo.signal(signal.SIGKILL) == -signal.SIGKILL
        until(
            lambda: not any(alive(pid) for pid in children),
            timeout=30,
            interval=0.2,
            message=lambda: f"still running: {[c for p, c in children.items() if alive(p)]}",
        )
    finally:
        demo.stop()
    _check_everything_ended(demo, children)


def test_a_port_in_use_is_named_and_nothing_is_started(tmp_path: Path) -> None:
    web_port, cobot_ports = free_port(), f"{free_port()},{free_port()}"
    with socket.socket() as holder:
        holder.bind(("127.0.0.1", web_port))
        holder.listen()
        result = subprocess.run(
            [sys.executable, "manage.py", "demo", "--port", str(web_port),
             "--cobot-ports", cobot_ports, "--logs", str(tmp_path / "logs")],
            cwd=ROOT, capture_output=True, text=True, timeout=120,
            env={**os.environ, "DJANGO_SETTINGS_MODULE": "hrc.settings.dev",
                 "DATABASE_URL": f"sqlite:///{tmp_path / 'demo.sqlite3'}"},
        )  # fmt: skip
    assert result.returncode == 1
    assert f"In use: 127.0.0.1:{web_port}" in result.stderr
    assert "--port" in result.stderr
    assert "migrating" not in result.stdout
    assert not (tmp_path / "logs").exists()


@pytest.mark.parametrize(
    ("variable", "url", "message"),
    [
        (
            "DATABASE_URL",
            "postgres://postgres@127.0.0.1:{port}/nothing",
            "The database does not answer",
        ),
        ("REDIS_URL", "redis://127.0.0.1:{port}/0", "REDIS_URL is set but Redis does not answer"),
    ],
)
def test_a_database_or_redis_that_does_not_answer_is_named_and_nothing_is_started(
    tmp_path: Path, variable: str, url: str, message: str
) -> None:
    environment = {
        **os.environ,
        "DJANGO_SETTINGS_MODULE": "hrc.settings.dev",
        "DATABASE_URL": f"sqlite:///{tmp_path / 'demo.sqlite3'}",
        variable: url.format(port=free_port()),  # nothing listens there
    }
    if variable == "DATABASE_URL":
        environment.pop("REDIS_URL", None)
    result = subprocess.run(
        [sys.executable, "manage.py", "demo", "--port", str(free_port()),
         "--cobot-ports", f"{free_port()},{free_port()}", "--logs", str(tmp_path / "logs")],
        cwd=ROOT, capture_output=True, text=True, timeout=120, env=environment,
    )  # fmt: skip
    assert result.returncode == 1
    assert message in result.stderr
    assert "Traceback" not in result.stderr
    assert not (tmp_path / "logs").exists()


RUNNING_NORMAL = (urua.ROBOT_MODE_RUNNING, urua.SAFETY_NORMAL)


def _cobot_states(demo: DemoRun) -> dict[str, tuple[str, str]]:
    """(RobotMode, SafetyMode) of each demo cobot, read from its gateway by this test."""
    states = {}
    for name, port in demo.cobot_ports.items():
        driver = driver_for(name, f"opc.tcp://127.0.0.1:{port}")
        try:
            state = driver.state()
        finally:
            driver.close()
        states[name] = (str(state["RobotMode"]), str(state["SafetyMode"]))
    return states


def _check_personas(demo: DemoRun) -> None:
    """Each persona signs in with the printed password and finds its first page; walls hold."""
    passwords = demo.passwords()
    assert set(passwords) == {persona.username for persona in PERSONAS}
    for persona in PERSONAS:
        wrong = Browserless(demo.url)
        assert not wrong.sign_in(persona.username, passwords[persona.username] + "x")
        person = Browserless(demo.url)
        assert person.sign_in(persona.username, passwords[persona.username]), persona
        for path in persona.pages:
            assert f"{demo.url}{path}" in demo.output()
            status, _, _ = person.get(path)
            assert status == 200, (persona.username, path)
        if persona.role == "operator":
            assert person.get("/cases/")[0] == 403
            assert person.get("/admin/")[1].startswith(f"{demo.url}/admin/login/")
        if persona.role == "admin":  # an organisation admin, not Django staff
            assert person.get("/admin/")[1].startswith(f"{demo.url}/admin/login/")


async def _reachable_cobots(demo: DemoRun, username: str, timeout: float = 60.0) -> set[str]:
    """The cobots a tablet of `username` sees reachable, waiting until all are or time runs out."""
    person = Browserless(demo.url)
    assert person.sign_in(username, demo.passwords()[username])
    status, _, page = person.get("/tablet/")
    assert status == 200
    match = CONFIG.search(page)
    assert match is not None
    config = json.loads(match.group(1))
    headers = {"Origin": demo.url, "Cookie": person.cookie_header()}
    url = f"ws://127.0.0.1:{demo.port}{config['socket']}"
    async with connect(url, additional_headers=headers) as socket:
        snapshot = json.loads(await asyncio.wait_for(socket.recv(), 10))
        assert snapshot["type"] == "snapshot"
        names = {cobot["id"]: cobot["name"] for cobot in snapshot["cobots"]}
        reachable = {c["id"] for c in snapshot["cobots"] if c["state"] and c["state"]["reachable"]}
        deadline = asyncio.get_running_loop().time() + timeout
        while reachable != set(names):
            remaining = deadline - asyncio.get_running_loop().time()
            if remaining <= 0:
                break
            event = json.loads(await asyncio.wait_for(socket.recv(), remaining))
            for state in event.get("states", []) if event["type"] == "cobot-state" else []:
                (reachable.add if state["reachable"] else reachable.discard)(state["cobot"])
    return {names[cobot] for cobot in reachable}


def _check_everything_ended(demo: DemoRun, children: dict[int, str]) -> None:
    assert children
    left = {pid: command for pid, command in children.items() if alive(pid)}
    assert not left, left
    for port in (demo.port, *demo.cobot_ports.values()):
        with socket.socket() as probe, pytest.raises(ConnectionRefusedError):
            probe.connect(("127.0.0.1", port))


def _check_passwords_only_printed(demo: DemoRun) -> None:
    """No file the demo wrote (logs, database, simulator state) holds a password in clear."""
    passwords = [password.encode() for password in demo.passwords().values()]
    written = [path for path in demo.workdir.rglob("*") if path.is_file() and path != demo.out]
    assert any(path.suffix == ".log" for path in written)
    for path in written:
        content = path.read_bytes()
        assert not any(password in content for password in passwords), path
