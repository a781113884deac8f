"""A database that cannot be reached: every kind of request answers 503 with a message."""

from __future__ import annotations

import json
import urllib.error
import urllib.request
from collections.abc import Iterator

import pytest

from hrc.cobots.simulated import free_port
from tests.live.server import LiveServer

API_REQUESTS: list[tuple[str, str, object]] = [
    ("GET", "/api/organisations/", None),
    ("POST", "/api/token/", {"username": "someone", "password": "secret"}),
    ("POST", "/api/work-items/1/complete/", {"data": {}}),
]


@pytest.fixture(scope="module")
def server(tmp_path_factory: pytest.TempPathFactory) -> Iterator[LiveServer]:
    # Nothing listens on that port: PostgreSQL is down as far as this server knows. The pool
    # gives up after a second instead of the default ten.
    log = tmp_path_factory.mktemp("unavailable") / "server.log"
    environment = {
        "DATABASE_URL": f"postgres://root@127.0.0.1:{free_port()}/test",
        "HRC_DB_POOL_TIMEOUT": "1",
    }
    live = LiveServer(log, environment).start(bare=True)
    yield live
    live.stop()


def _request(
    url: str, method: str = "GET", body: object = None, headers: dict[str, str] | None = None
) -> tuple[int, dict[str, str], str]:
    data = None if body is None else json.dumps(body).encode()
    request = urllib.request.Request(url, data=data, method=method, headers=headers or {})
    if data is not None:
        request.add_header("Content-Type", "application/json")
    try:
        with urllib.request.urlopen(request, timeout=30) as response:
            return response.status, dict(response.headers), response.read().decode()
    except urllib.error.HTTPError as error:
        return error.code, dict(error.headers), error.read().decode()


@pytest.mark.parametrize(("method", "path", "body"), API_REQUESTS)
def test_an_api_request_gets_503_with_a_message(
    server: LiveServer, method: str, path: str, body: object
) -> None:
    status, headers, text = _request(
        f"{server.url}{path}", method, body, {"Authorization": "Token 0123456789abcdef"}
    )
    assert status == 503
    assert headers["Content-Type"] == "application/json"
    assert headers["Retry-After"] == "5"
    assert "database is not answering" in json.loads(text)["detail"]


def test_a_page_gets_503_with_a_message(server: LiveServer) -> None:
    # A well-formed session key makes the page look its user up in the database.
    cookie = {"Cookie": f"sessionid={'a' * 32}"}
    status, headers, text = _request(f"{server.url}/cases/", headers=cookie)
    assert status == 503
    assert headers["Content-Type"].startswith("text/html")
    assert "The database is not answering" in text
    assert "Traceback" not in text


def test_the_cause_goes_to_the_servers_log(server: LiveServer) -> None:
    _request(f"{server.url}/api/organisations/", headers={"Authorization": "Token abc"})
    assert "GET /api/organisations/: the database is unavailable" in server.log.read_text()
