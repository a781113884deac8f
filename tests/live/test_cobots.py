"""The cobot panel over real sockets: a simulated gateway, the monitor process, the tablet's
throttle, and STOP / confirmed resume pausing and restarting the cell's cobots."""

from __future__ import annotations

import asyncio
import threading
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from django.contrib.auth.models import User
from rest_framework.test import APIClient

from hrc.cobots import stops
from hrc.cobots.drivers.base import Fence, StepCommand
from hrc.cobots.drivers.runner import SyncDriver, driver_for
from hrc.cobots.models import CellStop, Cobot
from hrc.cobots.simulated import GatewayProcess
from hrc.live.consumers import STATE_INTERVAL
from hrc.organisations import services as organisation_services
from hrc.organisations.models import Organisation
from hrc_gateway import urua
from tests import factories
from tests.cobots.simulator import PROGRAM
from tests.live.client import db, open_socket, receive, receive_until, run
from tests.live.server import LiveServer, MonitorProcess, session_cookie

pytestmark = pytest.mark.django_db(transaction=True)


@pytest.fixture
def gateway(tmp_path: Path) -> Iterator[GatewayProcess]:
    process = GatewayProcess("armA", tmp_path / "armA.json", time_scale=0.3).start()
    yield process
    driver_for("armA", process.endpoint).close()
    process.stop()


@pytest.fixture
def driver(gateway: GatewayProcess) -> SyncDriver:
    return driver_for("armA", gateway.endpoint, step_timeout=30.0)


@pytest.fixture
def cobot(organisation: Organisation, gateway: GatewayProcess) -> Cobot:
    return factories.make_cobot(organisation, name="armA", endpoint=gateway.endpoint, cell="A")


@pytest.fixture
def monitor(tmp_path: Path, cobot: Cobot) -> Iterator[MonitorProcess]:
    process = MonitorProcess(tmp_path / "monitor.log").start()
    yield process
    process.stop()


def _is_state(event: dict[str, Any], **wanted: Any) -> bool:
    return event["type"] == "cobot-state" and any(
        all(state.get(key) == value for key, value in wanted.items()) for state in event["states"]
    )


def test_the_panel_follows_the_gateway_at_most_ten_times_a_second(
    server: LiveServer, monitor: MonitorProcess, driver: SyncDriver, cobot: Cobot, operator: User
) -> None:
    cookie = session_cookie(operator)

    async def scenario() -> None:
        socket = await open_socket(server, cookie, "?cell=A")
        snapshot = await receive(socket)
        assert [c["name"] for c in snapshot["cobots"]] == ["armA"]
        await receive_until(socket, lambda e: _is_state(e, reachable=True))

        await asyncio.to_thread(driver.call, "PowerOn", timeout=30)
        await receive_until(socket, lambda e: _is_state(e, robot_mode=urua.ROBOT_MODE_RUNNING))
        await asyncio.to_thread(driver.call, "SelectProgram", PROGRAM)
        await asyncio.to_thread(driver.call, "StartProgram")

        # The arm moves for a while: joint positions change far more often than 10 times a second.
        moving = threading.Thread(target=_move_back_and_forth, args=(driver,), daemon=True)
        moving.start()
        frames: list[float] = []
        joints: set[tuple[float, ...]] = set()
        deadline = time.monotonic() + 3.0
        while time.monotonic() < deadline:
            try:
                event = await receive(socket, timeout=deadline - time.monotonic())
            except TimeoutError:
                break
            if event["type"] == "cobot-state":
                frames.append(time.monotonic())
                joints.update(tuple(s["joints"]) for s in event["states"])
        moving.join(60)
        assert len(joints) > 5  # it did follow the motion
        # In any one second, at most 10 frames (one more for the network's jitter at the edges).
        busiest = max(sum(1 for t in frames if start <= t < start + 1.0) for start in frames)
        assert busiest <= round(1 / STATE_INTERVAL) + 1
        assert len(frames) >= 10  # and it was not silent

    run(scenario())


def _move_back_and_forth(driver: SyncDriver) -> None:
    for attempt, workspace in enumerate([0, 1, 0, 1], start=1):
        command = StepCommand(step=2, fence=Fence(900 + attempt, 1), workspace=workspace)
        driver.run_step(command, timeout=30)


def test_a_tablet_of_another_cell_gets_no_state_of_this_one(
    server: LiveServer, monitor: MonitorProcess, cobot: Cobot, operator: User
) -> None:
    organisation_services.ensure_cell(cobot.organisation, "B")
    cookie = session_cookie(operator)

    async def scenario() -> None:
        elsewhere = await open_socket(server, cookie, "?cell=B")
        assert (await receive(elsewhere))["cobots"] == []
        here = await open_socket(server, cookie, "?cell=A")
        await receive(here)
        await receive_until(here, lambda e: _is_state(e, reachable=True))
        with pytest.raises(TimeoutError):
            await receive(elsewhere, timeout=1.0)

    run(scenario())


def test_stop_pauses_the_cell_and_only_a_confirmed_resume_restarts_it(
    server: LiveServer, driver: SyncDriver, cobot: Cobot, operator: User, organisation: Organisation
) -> None:
    driver.call("PowerOn", timeout=30)
    driver.call("SelectProgram", PROGRAM)
    driver.call("StartProgram")
    client = APIClient()
    client.force_authenticate(operator)
    cookie = session_cookie(operator)

    async def scenario() -> None:
        socket = await open_socket(server, cookie, "?cell=A")
        assert (await receive(socket))["stop"] is None
        response = await db(client.post, "/api/cells/stop/", {"cell": "A"}, format="json")
        assert response.status_code == 201, response.content
        assert driver.read(urua.STATE_PROGRAM_STATE) == urua.PROGRAM_PAUSED
        shown = await receive_until(socket, lambda e: e["type"] == "cell-stop")
        assert shown["stop"]["stopped_by"] == operator.username
        assert shown["stop"]["cobots"] == [cobot.pk]

        again = await db(client.post, "/api/cells/stop/", {"cell": "A"}, format="json")
        assert again.status_code == 200
        assert again.json()["id"] == shown["stop"]["id"]

        unconfirmed = await db(client.post, "/api/cells/resume/", {"cell": "A"}, format="json")
        assert unconfirmed.status_code == 400
        assert "confirm" in unconfirmed.json()["detail"]
        assert driver.read(urua.STATE_PROGRAM_STATE) == urua.PROGRAM_PAUSED

        resumed = await db(
            client.post, "/api/cells/resume/", {"cell": "A", "confirm": True}, format="json"
        )
        assert resumed.status_code == 200, resumed.content
        assert driver.read(urua.STATE_PROGRAM_STATE) == urua.PROGRAM_PLAYING
        ended = await receive_until(
            socket, lambda e: e["type"] == "cell-stop" and e["stop"]["resumed_at"] is not None
        )
        assert ended["stop"]["resumed_by"] == operator.username

    run(scenario())
    cobot.refresh_from_db()
    assert cobot.stopped_at is None
    assert CellStop.objects.get().resumed_at is not None


def test_resume_leaves_a_protective_stop_to_the_person_at_the_cell(
    driver: SyncDriver, cobot: Cobot, operator: User
) -> None:
    driver.call("PowerOn", timeout=30)
    driver.call("SelectProgram", PROGRAM)
    driver.call("StartProgram")
    client = APIClient()
    client.force_authenticate(operator)
    assert client.post("/api/cells/stop/", {"cell": "A"}, format="json").status_code == 201
    driver.call("Simulator/InjectFault", "protective-stop", "")

    resumed = client.post("/api/cells/resume/", {"cell": "A", "confirm": True}, format="json")

    assert resumed.status_code == 200
    assert "PROTECTIVE_STOP" in resumed.json()["problems"][str(cobot.pk)]
    assert driver.read(urua.STATE_SAFETY_MODE) == "SAFETY_MODE_PROTECTIVE_STOP"


def test_an_outsider_cannot_stop_our_cell(
    organisation: Organisation, outsider: User, cobot: Cobot
) -> None:
    client = APIClient()
    client.force_authenticate(outsider)

    refused = client.post(
        "/api/cells/stop/", {"organisation": organisation.pk, "cell": "A"}, format="json"
    )

    assert refused.status_code == 400
    assert "not a member" in refused.json()["detail"]
    assert not CellStop.objects.exists()
    cobot.refresh_from_db()
    assert cobot.stopped_at is None


@pytest.mark.parametrize("action", ["stop", "resume"])
def test_a_cell_the_organisation_does_not_have_cannot_be_stopped_or_resumed(
    organisation: Organisation, other_organisation: Organisation, operator: User, action: str
) -> None:
    cobot = factories.make_cobot(organisation, cell="A")
    organisation_services.ensure_cell(other_organisation, "cell1")
    client = APIClient()
    client.force_authenticate(operator)

    refused = client.post(
        f"/api/cells/{action}/", {"cell": "cell1", "confirm": True}, format="json"
    )

    assert refused.status_code == 400
    message = f"There is no cell 'cell1' in {organisation.name}."
    assert refused.json() == {"detail": message, "fields": {"cell": [message]}}
    assert not CellStop.objects.exists()
    cobot.refresh_from_db()
    assert cobot.stopped_at is None


@pytest.mark.parametrize("body", [{"cell": ""}, {}], ids=["empty cell", "no cell"])
@pytest.mark.parametrize("action", ["stop", "resume"])
def test_a_stop_or_resume_without_a_named_cell_is_a_400_naming_cell(
    organisation: Organisation,
    other_organisation: Organisation,
    operator: User,
    body: dict[str, str],
    action: str,
) -> None:
    # Cobots of no cell, ours and another organisation's: an empty cell once matched them.
    ours = factories.make_cobot(organisation)
    theirs = factories.make_cobot(other_organisation)
    client = APIClient()
    client.force_authenticate(operator)

    refused = client.post(f"/api/cells/{action}/", {**body, "confirm": True}, format="json")

    assert refused.status_code == 400
    assert "Name the cell" in refused.json()["fields"]["cell"][0]
    assert not CellStop.objects.exists()
    assert not Cobot.objects.filter(pk__in=[ours.pk, theirs.pk], stopped_at__isnull=False).exists()


def test_the_stop_service_refuses_an_empty_cell(organisation: Organisation, operator: User) -> None:
    factories.make_cobot(organisation)
    with pytest.raises(ValueError, match="names its cell"):
        stops.stop_cell(organisation, "", by=operator)
    assert not CellStop.objects.exists()


def test_a_quiet_cobots_subscription_is_kept_not_recreated(
    monitor: MonitorProcess, cobot: Cobot
) -> None:
    # Nothing happens at the cell; only the gateway's heartbeat keeps the subscription busy.
    time.sleep(4.0)

    assert "is stale" not in monitor.log.read_text()
