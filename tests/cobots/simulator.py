"""Looking at a simulated cobot from outside the driver, with a plain asyncua client."""

from __future__ import annotations

import asyncio
import time
from collections.abc import Callable
from typing import Any

from asyncua import Client

from hrc.cobots import urua

# Coexistence_PickAndPlace: 1 home, 2 move to a pose (ws 0 part box), 3 pick (a 2 s wait).
PROGRAM = "Coexistence_PickAndPlace"


async def read(client: Client, path: str) -> Any:
    return await client.get_node(urua.node_id("cobot1", path)).read_value()


async def executions(client: Client) -> int:
    """How many steps the simulator has run (counted by the simulator, not the driver)."""
    return int(await read(client, "Simulator/Executions"))


async def executed_steps(client: Client) -> list[str]:
    return list(await read(client, "Simulator/ExecutedSteps"))


async def until(condition: Callable[[], object], timeout: float = 5.0) -> None:
    """Polls `condition` every 5 ms until it holds; fails the test after `timeout` seconds."""
    deadline = time.monotonic() + timeout
    while not condition():
        assert time.monotonic() < deadline, "condition not reached in time"
        await asyncio.sleep(0.005)
