"""docker/healthcheck.py against the real processes it checks in compose: each check passes while
its service does its job and fails, saying why, once it does not."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest
from django.db import connection

from hrc.cobots.simulated import GatewayProcess
from hrc.organisations.models import Organisation
from tests import factories
from tests.live.server import LiveServer, MonitorProcess
from tests.support.paths import ROOT
from tests.support.polling import until
from tests.support.workers import RedisProcess, WorkerProcess


def _check(*arguments: str, environment: dict[str, str] | None = None) -> tuple[int, str]:
    result = subprocess.run(
        [sys.executable, "docker/healthcheck.py", *arguments],
        cwd=ROOT, capture_output=True, text=True, timeout=60,
        env={**os.environ, **(environment or {})},
    )  # fmt: skip
    return result.returncode, result.stderr


def _test_database() -> dict[str, str]:
    database = connection.settings_dict
    return {
        "DJANGO_SETTINGS_MODULE": "hrc.settings.test",
        "DATABASE_URL": f"postgres://{database['USER']}@{database['HOST']}:{database['PORT']}/{database['NAME']}",
    }


def test_gateway_is_healthy_while_its_opc_ua_port_accepts_connections(tmp_path: Path) -> None:
    gateway = GatewayProcess("cobot1", tmp_path / "cobot1.json").start()
    try:
        assert _check("gateway", str(gateway.port)) == (0, "")
    finally:
        gateway.kill()
    code, reason = _check("gateway", str(gateway.port))
    assert code == 1
    assert f"nothing accepts connections on port {gateway.port}" in reason


def test_beat_is_healthy_while_the_process_of_its_pid_file_lives(tmp_path: Path) -> None:
    pid_file = tmp_path / "celerybeat.pid"
    beat = subprocess.Popen(["sleep", "60"])
    pid_file.write_text(f"{beat.pid}\n")
    try:
        assert _check("beat", str(pid_file)) == (0, "")
    finally:
        beat.kill()
        beat.wait()
    code, reason = _check("beat", str(pid_file))
    assert code == 1
    assert "no beat process" in reason
    assert _check("beat")[0] == 1


def test_worker_is_healthy_while_it_answers_a_ping_over_the_broker(tmp_path: Path) -> None:
    broker = RedisProcess(tmp_path).start()
    environment = {"DJANGO_SETTINGS_MODULE": "hrc.settings.test", "REDIS_URL": broker.url}
    worker = WorkerProcess(tmp_path, name="worker", environment=environment).start()
    try:
        assert _check("worker", environment=environment) == (0, "")
        worker.stop()
        code, reason = _check("worker", environment=environment)
        assert code == 1
        assert "did not answer a ping" in reason
    finally:
        worker.kill()
        broker.stop()


@pytest.mark.django_db(transaction=True)
def test_web_is_healthy_while_daphne_serves_the_sign_in_page(tmp_path: Path) -> None:
    server = LiveServer(tmp_path / "web.log").start()
    try:
        assert _check("web", str(server.port)) == (0, "")
    finally:
        server.stop()
    code, reason = _check("web", str(server.port))
    assert code == 1
    assert "web: unhealthy" in reason


@pytest.mark.django_db(transaction=True)
def test_monitor_is_healthy_once_every_active_cobot_has_a_fresh_state(
    tmp_path: Path, organisation: Organisation
) -> None:
    gateway = GatewayProcess("cobot1", tmp_path / "cobot1.json").start()
    factories.make_cobot(organisation, name="cobot1", endpoint=gateway.endpoint)
    factories.make_cobot(organisation, name="retired", is_active=False)
    environment = _test_database()
    try:
        code, reason = _check("monitor", environment=environment)
        assert code == 1
        assert "no recent state from cobot1" in reason
        monitor = MonitorProcess(tmp_path / "monitor.log").start()
        try:
            until(
                lambda: _check("monitor", environment=environment)[0] == 0,
                timeout=30,
                interval=0.5,
                message=lambda: str(_check("monitor", environment=environment)),
            )
        finally:
            monitor.stop()
    finally:
        gateway.kill()
