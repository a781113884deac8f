"""Live-layer fixtures: a real ASGI server per test and real WebSocket clients."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest

from tests.live.server import LiveServer


@pytest.fixture
def server(tmp_path: Path, transactional_db: None) -> Iterator[LiveServer]:
    """An ASGI server on the test database and the shared Redis (this run's channel prefix)."""
    running = LiveServer(tmp_path / "server.log").start()
    yield running
    running.stop()
