"""Watches each cobot's gateway and broadcasts its state to the tablets (`manage.py live_cobots`).

One OPC UA session per cobot, with one subscription to the nodes the cobot
panel shows (modes, program, joint positions, the display device): the
gateway pushes every change, nothing is polled. Changes are coalesced per
cobot (at most one broadcast per `interval`, 50 ms by default), and the
consumer throttles again per tablet (10 a second); the state is also
re-sent every REFRESH_SECONDS, so the snapshot cache (cobot_states) never
goes stale while the gateway is quiet. A lost gateway is reported as
unreachable and reconnected with back-off.
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
import time
from dataclasses import dataclass, field
from typing import Any

from asgiref.sync import sync_to_async
from asyncua import Client, Node, ua
from django.conf import settings
from django.db import connections

from hrc.cobots.credentials import CredentialsError, credentials_for
from hrc.cobots.drivers.base import unreachable_message
from hrc.cobots.models import Cobot
from hrc.live import cobot_states, groups
from hrc.live.events import CobotStateData
from hrc_gateway import urua
from hrc_gateway.endpoints import check_networks
from hrc_gateway.pki import PkiError, secure_client

logger = logging.getLogger(__name__)

JOINTS = "Axes/ActualPositions/AxisPositions"
DISPLAY = "Devices/Display/Text"  # a device of the simulated cell; absent on most gateways
WATCHED = {
    urua.STATE_ROBOT_MODE: "robot_mode",
    urua.STATE_SAFETY_MODE: "safety_mode",
    urua.STATE_PROGRAM_STATE: "program_state",
    urua.STATE_CURRENT_PROGRAM: "program",
    urua.STATE_LAST_ERROR: "error",
    JOINTS: "joints",
}
REFRESH_SECONDS = 5.0
RELOAD_SECONDS = 10.0
BACKOFF = (0.5, 10.0)


@dataclass
class Watched:
    """One cobot as the monitor knows it: where to send its state, and the state."""

    cobot_id: int
    name: str
    endpoint: str
    credentials_source: str
    organisation: int
    cell: str
    state: CobotStateData = field(init=False)
    dirty: bool = True
    sent_at: float = 0.0

    def __post_init__(self) -> None:
        self.state = {
            "cobot": self.cobot_id, "at": time.time(), "reachable": False, "robot_mode": "",
            "safety_mode": "", "program_state": "", "program": "", "joints": [], "display": "",
            "display_at": 0.0, "error": "not connected yet",
        }  # fmt: skip

    def update(self, **values: Any) -> None:
        at = time.time()
        # The text's own time, kept while it stays: a reconnect or a resync shows it again
        # with the time it appeared, not as a new message.
        if "display" in values and values["display"] != self.state["display"]:
            values["display_at"] = at
        self.state = {**self.state, **values, "at": at}  # type: ignore[typeddict-item]
        self.dirty = True

    def recall_display(self, remembered: CobotStateData | None) -> None:
        """Takes the display text and its time from the state a monitor reported last (this one
        before a restart), so the text the cell still shows is not news."""
        if remembered is not None and remembered.get("display"):
            self.state = {
                **self.state,
                "display": remembered["display"],
                "display_at": remembered.get("display_at") or remembered["at"],
            }


class _Handler:
    def __init__(self, watched: Watched, paths: dict[ua.NodeId, str]) -> None:
        self.watched = watched
        self.paths = paths

    def datachange_notification(self, node: Node, value: Any, data: Any) -> None:
        path = self.paths.get(node.nodeid)
        if path == urua.STATE_HEARTBEAT:
            return  # it only keeps the subscription busy (see _watch)
        if path == DISPLAY:
            self.watched.update(display=str(value or ""))
        elif path == JOINTS:
            self.watched.update(joints=[round(float(v), 4) for v in value or []])
        elif path is not None:
            self.watched.update(**{WATCHED[path]: str(value or "")})

    def status_change_notification(self, status: Any) -> None:
        self.watched.update(reachable=False, error=f"subscription ended: {status}")


class Monitor:
    """Runs until cancelled: a watcher task per active cobot and one task that broadcasts."""

    def __init__(self, organisation: int | None = None, interval: float = 0.05) -> None:
        self.organisation = organisation
        self.interval = interval
        self.watched: dict[int, Watched] = {}
        self.tasks: dict[int, asyncio.Task[None]] = {}

    async def run(self) -> None:
        sender = asyncio.create_task(self._broadcast_forever())
        try:
            while True:
                await self._reload()
                await asyncio.sleep(RELOAD_SECONDS)
        finally:
            sender.cancel()
            for task in self.tasks.values():
                task.cancel()
            await asyncio.gather(sender, *self.tasks.values(), return_exceptions=True)

    async def _reload(self) -> None:
        rows = await sync_to_async(self._cobots)()
        current = {row.cobot_id: row for row in rows}
        for cobot_id in list(self.tasks):
            old, new = self.watched[cobot_id], current.get(cobot_id)
            if new is None or (old.endpoint, old.cell, old.credentials_source) != (
                new.endpoint, new.cell, new.credentials_source,
            ):  # fmt: skip
                self.tasks.pop(cobot_id).cancel()
                self.watched.pop(cobot_id)
        added = [cobot_id for cobot_id in current if cobot_id not in self.tasks]
        remembered = await sync_to_async(cobot_states.recall)(added) if added else {}
        for cobot_id, row in current.items():
            if cobot_id not in self.tasks:
                row.recall_display(remembered.get(cobot_id))
                self.watched[cobot_id] = row
                self.tasks[cobot_id] = asyncio.create_task(self._watch_forever(row))

    def _cobots(self) -> list[Watched]:
        cobots = Cobot.objects.filter(is_active=True)
        if self.organisation is not None:
            cobots = cobots.filter(organisation_id=self.organisation)
        try:
            return [
                Watched(c.pk, c.name, c.endpoint, c.credentials_source, c.organisation_id, c.cell)
                for c in cobots
            ]
        finally:
            connections.close_all()  # one read every RELOAD_SECONDS: no connection held between

    async def _watch_forever(self, watched: Watched) -> None:
        delay = BACKOFF[0]
        while True:
            try:
                await self._watch(watched)
                delay = BACKOFF[0]
            except asyncio.CancelledError:
                raise
            except CredentialsError as error:  # the organisation's own set-up, said as it is
                watched.update(reachable=False, error=str(error))
            except Exception as error:  # any failure of the session: report it, try again
                # One message whatever is at the endpoint (no port oracle); the detail is logged.
                logger.warning(
                    "Cannot watch cobot %s at %s: %s",
                    watched.name, watched.endpoint, error or type(error).__name__,
                )  # fmt: skip
                watched.update(reachable=False, error=unreachable_message(watched.name))
            await asyncio.sleep(delay)
            delay = min(delay * 2, BACKOFF[1])

    async def _watch(self, watched: Watched) -> None:
        await check_networks(watched.endpoint, settings.HRC_COBOT_NETWORKS)
        client = Client(watched.endpoint, timeout=4)
        client.name = client.description = f"hrc live monitor for {watched.name}"
        credentials = await sync_to_async(_credentials)(watched)
        if credentials is not None:
            try:
                await secure_client(client, settings.HRC_PKI_DIR, watched.name, *credentials)
            except PkiError as error:
                raise ConnectionError(str(error)) from None
        lost = asyncio.Event()

        async def on_lost(error: Exception) -> None:
            lost.set()

        client.connection_lost_callback = on_lost
        await asyncio.wait_for(client.connect(), 5)
        try:
            # The gateway's heartbeat changes 4 times a second: without it a quiet cobot's
            # subscription looks stale to asyncua (publishing interval 0) and is recreated.
            watched_paths = [*WATCHED, urua.STATE_HEARTBEAT]
            paths = {
                client.get_node(urua.node_id(watched.name, p)).nodeid: p for p in watched_paths
            }
            handler = _Handler(watched, paths)
            parameters = ua.CreateSubscriptionParameters(
                RequestedPublishingInterval=0, RequestedLifetimeCount=300,
                RequestedMaxKeepAliveCount=20, PublishingEnabled=True,
            )  # fmt: skip
            subscription = await client.create_subscription(parameters, handler)
            await subscription.subscribe_data_change(
                [client.get_node(node_id) for node_id in paths], queuesize=1, sampling_interval=0
            )
            display = client.get_node(urua.node_id(watched.name, DISPLAY))
            with contextlib.suppress(ua.UaError):  # a gateway without the display device
                await display.read_value()
                paths[display.nodeid] = DISPLAY
                await subscription.subscribe_data_change([display], queuesize=1)
            watched.update(reachable=True, error="")
            await lost.wait()
            watched.update(
                reachable=False, error=f"{watched.name}: lost the connection to the cobot."
            )
        finally:
            with contextlib.suppress(Exception):
                await asyncio.wait_for(client.disconnect(), 2)

    async def _broadcast_forever(self) -> None:
        while True:
            await asyncio.sleep(self.interval)
            now = time.monotonic()
            for watched in list(self.watched.values()):
                if watched.dirty or now - watched.sent_at > REFRESH_SECONDS:
                    watched.dirty, watched.sent_at = False, now
                    try:
                        await groups.send_cobot_state(
                            watched.state, organisation=watched.organisation, cell=watched.cell
                        )
                        await sync_to_async(cobot_states.remember)(watched.state)
                    except Exception:
                        logger.exception("Could not broadcast %s's state", watched.name)


def _credentials(watched: Watched) -> tuple[str, str] | None:
    """The cobot's credentials, from a secret of its own organisation only."""
    try:
        return credentials_for(watched.name, watched.organisation, watched.credentials_source)
    finally:
        connections.close_all()  # read from a worker thread: hold no connection after
