"""A secured gateway process and the driver: Basic256Sha256 SignAndEncrypt, user names, pinning."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest
from asyncua import Client
from django.core.management import call_command

from hrc.cobots.drivers.base import CobotUnreachable, Fence, StepCommand, unreachable_message
from hrc.cobots.drivers.opcua.driver import ClientSecurity, OpcUaDriver
from hrc.cobots.simulated import GatewayProcess
from tests.cobots.simulator import PROGRAM

PASSWORD = "correct horse battery staple"


@pytest.fixture
def pki(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("COBOT1_PASSWORD", PASSWORD)
    directory = tmp_path / "pki"
    call_command(
        "cobot_certificates", "cobot1", "--pki", str(directory),
        "--user", "hrc-driver", "--password-env", "COBOT1_PASSWORD",
    )  # fmt: skip
    return directory


@pytest.fixture
def secure_gateway(tmp_path: Path, pki: Path) -> Iterator[GatewayProcess]:
    process = GatewayProcess("cobot1", tmp_path / "cobot1.json", extra=("--pki", str(pki)))
    yield process.start()
    process.stop()


async def test_the_driver_runs_a_step_over_an_encrypted_session(
    secure_gateway: GatewayProcess, pki: Path
) -> None:
    driver = OpcUaDriver(
        "cobot1", secure_gateway.endpoint, security=ClientSecurity(pki, "hrc-driver", PASSWORD)
    )
    try:
        await driver.call("PowerOn", timeout=20)
        await driver.call("SelectProgram", PROGRAM)
        await driver.call("StartProgram")
        result = await driver.run_step(StepCommand(step=3, fence=Fence(1, 1)))
        assert result.outcome == "ran"
    finally:
        await driver.close()


async def test_a_wrong_password_reads_as_unreachable_and_is_named_in_the_log(
    secure_gateway: GatewayProcess, pki: Path, caplog: pytest.LogCaptureFixture
) -> None:
    # Saying "wrong password" would tell an engineer probing ports that a gateway listens there.
    driver = OpcUaDriver(
        "cobot1",
        secure_gateway.endpoint,
        security=ClientSecurity(pki, "hrc-driver", "guess"),
        connect_timeout=2.0,
    )
    with pytest.raises(CobotUnreachable) as refused:
        await driver.state()
    assert str(refused.value) == unreachable_message("cobot1")
    assert "refused the user name or password" in caplog.text
    await driver.close()


async def test_an_anonymous_unencrypted_client_is_refused(secure_gateway: GatewayProcess) -> None:
    client = Client(secure_gateway.endpoint, timeout=3)
    with pytest.raises(Exception):  # noqa: B017,PT011 - asyncua refuses before any session exists
        await client.connect()
    await client.disconnect()
