"""Looking at a simulated cobot from outside the driver, with a plain asyncua client."""

from __future__ import annotations

import asyncio
import json
from pathlib import Path
from typing import Any

from asyncua import Client

from hrc_gateway import urua
from hrc_gateway.sim.backend import SimBackend
from hrc_gateway.sim.robot import IDLE

# Coexistence_PickAndPlace: 1 home, 2 move to a pose (ws 0 part box), 3 pick (a 2 s wait).
PROGRAM = "Coexistence_PickAndPlace"


async def read(client: Client, path: str) -> Any:
    return await client.get_node(urua.node_id("cobot1", path)).read_value()


async def executions(client: Client) -> int:
    """How many steps the simulator has run (counted by the simulator, not the driver)."""
    return int(await read(client, "Simulator/Executions"))


async def executed_steps(client: Client) -> list[str]:
    return list(await read(client, "Simulator/ExecutedSteps"))


def save_arm_powered_to_idle(state_file: Path, name: str = "cobot1") -> None:
    """Saves a simulator state whose arm a person powered on at the pendant, brakes still on.

    The simulator's own PowerOn goes on to Running; a controller left in Idle
    is what a gateway (re)started beside such an arm finds.
    """

    async def fresh_state() -> None:
        backend = SimBackend(name, time_scale=0, state_file=state_file)
        await backend.start(_NoSpace(), _ignore)
        await backend.close()

    asyncio.run(fresh_state())
    leave_arm_in_idle(state_file)


def leave_arm_in_idle(state_file: Path) -> None:
    """Edits a saved simulator state: its arm is powered, in Idle, brakes on."""
    data = json.loads(state_file.read_text(encoding="utf-8"))
    data["arm"]["robot_mode"] = IDLE
    state_file.write_text(json.dumps(data), encoding="utf-8")


class _NoSpace:
    async def add_variable(self, *args: Any, **kwargs: Any) -> None:
        return None

    async def add_method(self, *args: Any, **kwargs: Any) -> None:
        return None

    async def drop_connections(self) -> None:
        return None


async def _ignore(values: Any) -> None:
    return None
