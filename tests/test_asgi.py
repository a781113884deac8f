"""The web process as production runs it: ASGI (daphne), on the test database."""

from __future__ import annotations

import urllib.request
from pathlib import Path

import pytest
from django.contrib.auth.models import User

from tests import factories
from tests.live.server import LiveServer
from tests.postgres import sessions_opened

REQUESTS = 10


@pytest.mark.django_db(transaction=True)
def test_requests_share_the_pools_database_sessions(tmp_path: Path, operator: User) -> None:
    # Under ASGI each request runs on a thread of its own: with persistent connections
    # (CONN_MAX_AGE) instead of the pool, each would open a session of its own.
    server = LiveServer(tmp_path / "server.log").start()
    token = factories.api_key(operator)
    request = urllib.request.Request(
        f"{server.url}/api/organisations/", headers={"Authorization": f"Token {token}"}
    )
    try:
        urllib.request.urlopen(request, timeout=10).close()  # the pool opens its first one
        before = sessions_opened()
        for _ in range(REQUESTS):
            with urllib.request.urlopen(request, timeout=10) as response:
                assert response.status == 200
        opened = sessions_opened() - before
    finally:
        server.stop()
    assert opened <= 2  # the pool's own, counted late, and perhaps one more it keeps ready
