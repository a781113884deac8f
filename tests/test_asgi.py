"""The web process as production runs it: ASGI (daphne), on the test database."""

from __future__ import annotations

import json
import urllib.error
import urllib.request
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest
from django.contrib.auth.models import User

from hrc.organisations.models import Organisation
from tests import factories
from tests.engine.builders import parallel_lanes
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


# The probe's requests that once held a connection, a worker thread or the CPU.
HOSTILE = [
    ("GET", "/api/analytics/xes/?version={version}&since=2026-01-01T00:00:00%2B23:00", None),
    ("GET", "/api/analytics/xes/?version={version}&until=2026-01-01T00:00:00%2B23:08", None),
    ("GET", "/api/patterns/?limit=9223372036854775808", None),
    ("GET", "/api/cases/?limit=99999999999999999999&offset=-1", None),
    ("POST", "/api/work-items/%C2%B2/claim/", b"{}"),
    ("POST", "/api/cells/stop/", b'{"cell": ""}'),
    # 20 KB whose state space took 9 s of the server's CPU per check.
    ("POST", "/api/patterns/check-document/", json.dumps(parallel_lanes(10, 8)).encode()),
]
HOSTILE_REQUESTS = 50
DROPPED = 0


@pytest.mark.django_db(transaction=True)
def test_after_fifty_hostile_requests_at_once_the_server_still_answers(
    tmp_path: Path, engineer: User, organisation: Organisation
) -> None:
    version = factories.make_version(organisation, published_by=engineer)
    key = factories.api_key(engineer)
    headers = {"Authorization": f"Token {key}", "Content-Type": "application/json"}
    server = LiveServer(tmp_path / "server.log").start(bare=True)

    def hostile(n: int) -> int:
        method, path, body = HOSTILE[n % len(HOSTILE)]
        url = f"{server.url}{path.format(version=version.pk)}"
        request = urllib.request.Request(url, body, headers, method=method)
        try:
            with urllib.request.urlopen(request, timeout=60) as response:
                response.read()
                return int(response.status)
        except urllib.error.HTTPError as refused:
            return refused.code
        except ConnectionError:
            return DROPPED  # a hostile request may be cut short; the server must live on

    try:
        with ThreadPoolExecutor(HOSTILE_REQUESTS) as pool:
            answers = list(pool.map(hostile, range(HOSTILE_REQUESTS)))
        plain = urllib.request.Request(f"{server.url}/api/organisations/", headers=headers)
        with urllib.request.urlopen(plain, timeout=1) as response:
            assert response.status == 200
    finally:
        server.stop()
    assert all(answer < 500 for answer in answers), answers
