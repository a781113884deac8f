"""Each step executes exactly once, whatever dies in the middle.

The simulator counts executions itself (Simulator/Executions and
ExecutedSteps), so these tests count what the cobot did, not what the
driver believes.
"""

from __future__ import annotations

import asyncio
import signal
import subprocess
import sys
from pathlib import Path

from asyncua import Client, ua

from hrc.cobots.drivers.base import Fence, StepCommand
from hrc.cobots.drivers.opcua.driver import OpcUaDriver
from hrc.cobots.simulated import GatewayProcess
from hrc_gateway import urua
from tests.cobots.simulator import PROGRAM, executed_steps, executions, read
from tests.support.paths import ROOT
from tests.support.polling import until_async

PICK = 3  # Coexistence_PickAndPlace: a 2 s (simulated) pick
IN_BIT = urua.register_path("Inputs", "Bit64")
OUT_BIT = urua.register_path("Outputs", "Bit64")


async def test_a_client_killed_mid_handshake_does_not_run_the_step_twice(
    driver: OpcUaDriver, gateway: GatewayProcess, observer: Client
) -> None:
    # Twenty times slower steps, so the kill surely lands before the acknowledgement.
    await driver.call("Simulator/InjectFault", "slow-steps", "20")
    client = subprocess.Popen(
        [
            sys.executable,
            str(ROOT / "manage.py"),
            "cobot_step",
            "cobot1",
            "--endpoint",
            gateway.endpoint,
            "--step",
            str(PICK),
            "--fence",
            "500.1",
        ],
        cwd=ROOT,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    try:
        await _until_value(observer, IN_BIT, True, timeout=30)
        client.send_signal(signal.SIGKILL)  # mid-step: the bit is up, no acknowledgement yet
        client.wait(10)
    finally:
        if client.poll() is None:
            client.kill()
    assert await read(observer, OUT_BIT) is False
    # The restarted client sends the same token: it waits for the step in flight.
    result = await driver.run_step(StepCommand(step=PICK, fence=Fence(500, 1)))
    assert (result.sent, result.outcome) == (False, "ran")
    assert await executions(observer) == 1
    assert await read(observer, IN_BIT) is False


async def test_a_client_that_died_before_clearing_the_bit_is_finished_not_repeated(
    driver: OpcUaDriver, observer: Client
) -> None:
    # A dead client's half handshake: data and bit written, acknowledged, never cleared.
    await _prototype_write(observer, {"Int24": PICK, "Int26": 501, "Int27": 1, "Bit64": True})
    await _until_value(observer, OUT_BIT, True)
    result = await driver.run_step(StepCommand(step=PICK, fence=Fence(501, 1)))
    assert (result.sent, result.outcome) == (False, "ran")
    assert await read(observer, IN_BIT) is False
    assert await read(observer, OUT_BIT) is False
    assert await executions(observer) == 1


async def test_a_gateway_restarted_mid_step_finishes_the_step_once(tmp_path: Path) -> None:
    # Slower time so the kill lands inside the step (a 2 s pick takes 0.4 s here).
    gateway = GatewayProcess("cobot1", tmp_path / "cobot1.json", time_scale=0.2).start()
    driver = OpcUaDriver("cobot1", gateway.endpoint, step_timeout=60, backoff=(0.05, 0.5))
    try:
        await driver.call("PowerOn", timeout=30)
        await driver.call("SelectProgram", PROGRAM)
        await driver.call("StartProgram")
        step = asyncio.create_task(driver.run_step(StepCommand(step=PICK, fence=Fence(600, 1))))
        await until_async(lambda: driver.cache.get(IN_BIT) is True, timeout=10)
        gateway.kill()
        await asyncio.sleep(0.3)
        await asyncio.to_thread(gateway.start)
        result = await asyncio.wait_for(step, 60)
        assert result.outcome == "ran"
        ran = await driver.read("Simulator/ExecutedSteps")
        assert [line.split()[0] for line in ran] == ["600.1"]
        assert await driver.read("Simulator/Executions") == 1
    finally:
        await driver.close()
        gateway.stop()


async def test_the_same_step_sent_by_two_clients_at_once_runs_once(
    driver: OpcUaDriver, gateway: GatewayProcess, observer: Client
) -> None:
    other = OpcUaDriver("cobot1", gateway.endpoint, step_timeout=20)
    command = StepCommand(step=PICK, fence=Fence(700, 1))
    try:
        results = await asyncio.gather(driver.run_step(command), other.run_step(command))
    finally:
        await other.close()
    assert sorted(r.sent for r in results) in ([False, True], [True, True])
    assert all(r.outcome in ("ran", "duplicate") for r in results)
    assert await executions(observer) == 1
    assert [line.split()[0] for line in await executed_steps(observer)] == ["700.1"]


async def _prototype_write(client: Client, registers: dict[str, object]) -> None:
    nodes, values = [], []
    for name, value in registers.items():
        nodes.append(client.get_node(urua.node_id("cobot1", urua.register_path("Inputs", name))))
        kind = urua.register_kind(name)
        vtype = {"Bit": ua.VariantType.Boolean, "Int": ua.VariantType.Int32}.get(
            kind, ua.VariantType.Double
        )
        values.append(ua.DataValue(ua.Variant(value, vtype)))
    await client.write_values(nodes, values)


async def _until_value(client: Client, path: str, value: object, timeout: float = 10) -> None:
    async def reached() -> bool:
        return bool(await read(client, path) == value)

    await until_async(reached, timeout, message=f"{path} never became {value!r}")
