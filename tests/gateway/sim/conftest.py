from collections.abc import AsyncIterator

import pytest

from tests.gateway.sim.cell import Cell


@pytest.fixture
async def cell() -> AsyncIterator[Cell]:
    """A cell at 50× speed: a 2 s tool wait takes 40 ms."""
    started = await Cell.start()
    yield started
    await started.close()
