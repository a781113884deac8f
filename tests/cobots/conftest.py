"""Simulated cobot gateways for the cobot tests: a real gateway process per test."""

from __future__ import annotations

from collections.abc import AsyncIterator, Iterator
from pathlib import Path

import pytest
from asyncua import Client

from hrc.cobots.drivers.opcua.driver import OpcUaDriver
from hrc.cobots.simulated import GatewayProcess
from tests.cobots.simulator import PROGRAM


@pytest.fixture
def gateway(tmp_path: Path) -> Iterator[GatewayProcess]:
    process = GatewayProcess("cobot1", tmp_path / "cobot1.json").start()
    yield process
    process.stop()


@pytest.fixture
async def driver(gateway: GatewayProcess) -> AsyncIterator[OpcUaDriver]:
    """A driver to a cobot that is powered on and playing PROGRAM."""
    driver = OpcUaDriver("cobot1", gateway.endpoint, step_timeout=20.0, connect_timeout=5.0)
    await driver.call("PowerOn", timeout=20)
    await driver.call("SelectProgram", PROGRAM)
    await driver.call("StartProgram")
    yield driver
    await driver.close()


@pytest.fixture
async def observer(gateway: GatewayProcess) -> AsyncIterator[Client]:
    """A plain asyncua client for looking at the simulator from outside the driver."""
    client = Client(gateway.endpoint)
    await client.connect()
    yield client
    await client.disconnect()
