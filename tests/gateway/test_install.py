"""The gateway installs alone in a fresh venv and serves a simulated cobot from its own entry point.

It is deployed per cobot, beside the robot, where the web application is not:
`pip install ./hrc_gateway` with only its declared dependencies (pinned by the
project's lock), then `hrc-gateway`. The test process talks to it over OPC UA.
"""

from __future__ import annotations

import shutil
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import pytest
from asyncua import Client

from hrc.cobots.simulated import free_port
from hrc_gateway import urua
from tests.support.paths import ROOT


@pytest.fixture(scope="module")
def venv(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A venv holding the gateway package and its dependencies, nothing else."""
    scratch = tmp_path_factory.mktemp("gateway-venv")
    # pip builds in the source folder: a copy keeps build/ and *.egg-info out of the tree.
    source = scratch / "hrc_gateway"
    shutil.copytree(
        ROOT / "hrc_gateway",
        source,
        ignore=shutil.ignore_patterns("__pycache__", "build", "*.egg-info"),
    )
    venv = scratch / "venv"
    subprocess.run([sys.executable, "-m", "venv", "--without-pip", str(venv)], check=True)
    python = venv / "bin" / "python"
    # This venv's pip installs into the new one (--python): no pip to bootstrap there.
    installed = subprocess.run(
        [sys.executable, "-m", "pip", "--python", str(python), "install", "--quiet",
         "-c", str(ROOT / "requirements" / "lock.txt"), str(source)],
        capture_output=True, text=True, timeout=600, check=False,
    )  # fmt: skip
    assert installed.returncode == 0, installed.stdout + installed.stderr
    return venv


def test_the_venv_holds_the_gateway_and_not_the_web_application(venv: Path) -> None:
    script = (
        "import importlib.util as u; "
        "print([m for m in ('hrc_gateway', 'asyncua', 'django', 'celery', 'hrc', 'rtde_io') "
        "if u.find_spec(m)])"
    )
    found = subprocess.run(
        [venv / "bin" / "python", "-c", script],
        cwd=venv,  # not the repository, whose packages would be importable from there
        capture_output=True, text=True, check=True,
    )  # fmt: skip
    assert found.stdout.strip() == "['hrc_gateway', 'asyncua']"


@pytest.fixture
def gateway(venv: Path, tmp_path: Path) -> Iterator[str]:
    """`hrc-gateway` serving a simulated cobot1 on loopback, from the fresh venv; its endpoint."""
    port = free_port()
    log = tmp_path / "gateway.log"
    with log.open("wb") as out:
        process = subprocess.Popen(
            [venv / "bin" / "hrc-gateway", "--name", "cobot1", "--port", str(port),
             "--insecure", "--time-scale", "0", "--state-file", tmp_path / "cobot1.json"],
            cwd=tmp_path, stdout=out, stderr=subprocess.STDOUT,
        )  # fmt: skip
    try:
        deadline = time.monotonic() + 30
        while "gateway serving" not in log.read_text():
            assert process.poll() is None, log.read_text()
            assert time.monotonic() < deadline, log.read_text()
            time.sleep(0.05)
        yield f"opc.tcp://127.0.0.1:{port}"
        process.send_signal(signal.SIGTERM)
        assert process.wait(10) == 0, log.read_text()  # a clean stop
    finally:
        if process.poll() is None:
            process.kill()
            process.wait(10)


async def test_the_installed_gateway_serves_a_simulated_cobot(gateway: str) -> None:
    async with Client(gateway) as client:
        mode = client.get_node(urua.node_id("cobot1", urua.STATE_ROBOT_MODE))
        assert await mode.read_value() == urua.ROBOT_MODE_POWER_OFF
        await client.get_node(urua.node_id("cobot1")).call_method("2:PowerOn")
        assert await mode.read_value() == urua.ROBOT_MODE_RUNNING
