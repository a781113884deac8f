"""What makes a started demo a living plant: cobots prepared at the pendant, a few cases running.

`manage.py demo` calls these once every process serves. Preparing a cobot
is what a person at its pendant does on a fresh cell (power on, release the
brakes), done here over the gateway's endpoint and never through a case: the
software that runs cases never powers a cobot on by itself. It loads no
program; the worker loads each step's own. The cases start as an engineer
starts them, through the running server's REST API, so their jobs run where
the server's run (its threads on the embedded default, the worker with
Redis), not in the demo command's process.
"""

from __future__ import annotations

import json
import time
import urllib.error
import urllib.request
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

from hrc.cobots.drivers.base import DriverError
from hrc.cobots.drivers.runner import driver_for
from hrc_gateway import urua

# Seconds a cobot may take from PowerOn to Running; the simulator needs 1.5 s at --time-scale 1.
PREPARE_TIMEOUT = 30.0
# The use cases a demo starts, each on one of its cobots: (pattern name, cobot actor → cobot).
# Polishing checks the cobot's lines one by one; the fixture asks the operator where each part
# goes (a form) while the cobot holds it. Each has one cobot, so the two run side by side.
STARTED_CASES: tuple[tuple[str, Mapping[str, str]], ...] = (
    ("Use case 5: polishing (1 operator, 1 cobot)", {"c": "cobot1"}),
    ("Use case 6: fixture (1 operator, 1 cobot)", {"c": "cobot2"}),
)


@dataclass(frozen=True)
class Preparation:
    """One cobot after the attempt to prepare it: `problem` is None when it is Running."""

    cobot: str
    problem: str | None = None


@dataclass(frozen=True)
class StartedCase:
    pattern: str
    case: int


class CasesNotStarted(Exception):
    """The server refused or did not answer; the message says what it said."""


def prepare_cobots(
    endpoints: Mapping[str, str], timeout: float = PREPARE_TIMEOUT
) -> list[Preparation]:
    """Powers each cobot on and releases its brakes (URUA PowerOn), as a person at the pendant.

    Returns, per cobot, whether it reported RobotMode Running within
    `timeout` seconds, or what stood in the way and what a person does. A
    protective or emergency stop is left as it is: only a person clears it.
    """
    preparations = []
    for name, endpoint in endpoints.items():
        driver = driver_for(name, endpoint, connect_timeout=10.0)
        try:
            driver.call("PowerOn", timeout=timeout)
            mode = _wait_running(driver.state, timeout)
        except DriverError as error:
            # The driver's message starts with the cobot's name, which the banner says already.
            message = str(error).removeprefix(f"{name}: ")
            preparations.append(Preparation(name, f"{message} {_remedy(name)}"))
            continue
        finally:
            driver.close()
        problem = None if mode == urua.ROBOT_MODE_RUNNING else f"it is {mode!r} after PowerOn."
        preparations.append(Preparation(name, problem and f"{problem} {_remedy(name)}"))
    return preparations


def _wait_running(state: Callable[[], Mapping[str, Any]], timeout: float) -> str:
    """The cobot's RobotMode once it is Running, or the last one seen after `timeout` seconds."""
    deadline = time.monotonic() + timeout
    mode = str(state()["RobotMode"])
    while mode != urua.ROBOT_MODE_RUNNING and time.monotonic() < deadline:
        time.sleep(0.2)
        mode = str(state()["RobotMode"])
    return mode


def _remedy(name: str) -> str:
    return (
        f"In the demo, as that person: manage.py cobot_fault {name} unlock, then power it on "
        f"from its page under /cobots/ or with manage.py cobot_call {name} PowerOn."
    )


def start_cases(
    url: str, username: str, password: str, cobot_ids: Mapping[str, int]
) -> list[StartedCase]:
    """Starts STARTED_CASES on the server at `url` as `username`, through the REST API.

    `cobot_ids` maps the demo's cobot names to their ids. Raises
    CasesNotStarted with the server's answer when it refuses one.
    """
    token = _request(url, "POST", "/api/token/", {"username": username, "password": password})
    headers = {"Authorization": f"Token {token['token']}"}
    patterns = _request(url, "GET", "/api/patterns/?limit=1000", headers=headers)["results"]
    pattern_ids = {pattern["name"]: pattern["id"] for pattern in patterns}
    started = []
    for name, cobots in STARTED_CASES:
        if name not in pattern_ids:
            raise CasesNotStarted(f"{name!r} is not published in the demo organisation.")
        # Newest first (the API's order): a case runs the latest published version.
        path = f"/api/pattern-versions/?pattern={pattern_ids[name]}&limit=1"
        newest = _request(url, "GET", path, headers=headers)["results"]
        if not newest:
            raise CasesNotStarted(f"{name!r} has no published version.")
        mapping = {actor: {"cobot": cobot_ids[cobot]} for actor, cobot in cobots.items()}
        body = {"version": newest[0]["id"], "actor_mapping": mapping}
        case = _request(url, "POST", "/api/cases/", body, headers=headers)
        started.append(StartedCase(name, int(case["id"])))
    return started


def _request(
    url: str,
    method: str,
    path: str,
    body: Mapping[str, Any] | None = None,
    headers: Mapping[str, str] | None = None,
) -> Any:
    request = urllib.request.Request(
        f"{url}{path}",
        method=method,
        data=None if body is None else json.dumps(body).encode(),
        headers={
            "Content-Type": "application/json",
            "Accept": "application/json",
            **(headers or {}),
        },
    )
    try:
        with urllib.request.urlopen(request, timeout=30) as response:
            return json.load(response)
    except urllib.error.HTTPError as error:
        answer = error.read().decode(errors="replace")[:500]
        raise CasesNotStarted(f"{method} {path} answered {error.code}: {answer}") from None
    except OSError as error:
        raise CasesNotStarted(f"{method} {path} did not answer: {error}") from None
