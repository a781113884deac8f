"""The tablets' WebSocket: /ws/live/?organisation=<id>&cell=<cell>. Thin: the rules live in
selectors (who may watch, the snapshot) and groups (the deltas).

On connect: refused (a `refused` event, then close 4401/4403) unless the
session's user is a member of the organisation, and (4404) when the cell is
none of the organisation's; then the socket joins its
groups and only then reads the snapshot (hrc.live.events explains why). The
deltas pass through as they come, except the cobot states (below); every send
first re-checks that the event is the organisation's and the cell's, and that
the user's membership still holds.
An admin who ends a membership closes the user's sockets at once (a
`membership.ended` message to the user's group); as a backstop, memberships
are read again every RECHECK_SECONDS for all the process's sockets in one
query (Memberships), not per socket and send: 200 tablets would otherwise
queue 200 reads in front of one delta. A socket whose membership is gone is
refused and closed. `cobot-state` deltas are
coalesced: at most one frame per STATE_INTERVAL per socket.
"""

from __future__ import annotations

import asyncio
import time
from typing import Any
from urllib.parse import parse_qs

from channels.db import database_sync_to_async
from channels.generic.websocket import AsyncJsonWebsocketConsumer
from channels.layers import InMemoryChannelLayer

from hrc.live import groups, selectors
from hrc.live.events import CobotStateData, LiveEvent
from hrc.live.selectors import Access
from hrc.organisations.validators import validate_cell

# Seconds between two reads of the connected sockets' memberships.
RECHECK_SECONDS = 5.0
# At most 10 cobot-state frames a second per tablet.
STATE_INTERVAL = 0.1
# Event types about one cobot: only its cell's tablets (and the whole floor's) get them.
CELL_SCOPED = frozenset({"cobot-state", "cobot-queue"})
# The deltas a tablet gets as they come; `cobot-state` is coalesced; anything else is dropped.
PASSED_ON = frozenset({"case", "work-item", "incident", "cobot-queue", "cell-stop"})
UNAUTHENTICATED = 4401
FORBIDDEN = 4403
NOT_FOUND = 4404


class TabletConsumer(AsyncJsonWebsocketConsumer):  # type: ignore[misc]  # channels is untyped
    access: Access | None = None
    cell: str = ""
    groups_joined: list[str]

    async def connect(self) -> None:
        if isinstance(self.channel_layer, InMemoryChannelLayer):
            groups.serve_from(asyncio.get_running_loop())  # the embedded demo's layer
        self.groups_joined = []
        self._states: dict[int, CobotStateData] = {}
        self._state_flush: asyncio.TimerHandle | None = None
        self._last_state_frame = 0.0
        await self.accept()
        user = self.scope.get("user")
        if user is None or not user.is_authenticated:
            await self._refuse("Sign in first.", UNAUTHENTICATED)
            return
        try:
            organisation, self.cell = _parameters(self.scope.get("query_string", b""))
        except ValueError as error:
            await self._refuse(str(error), FORBIDDEN)
            return
        self.access = await database_sync_to_async(selectors.access_of)(user, organisation)
        if self.access is None:
            await self._refuse("You are not a member of this organisation.", FORBIDDEN)
            return
        access = self.access
        if not await database_sync_to_async(selectors.is_cell)(access.organisation_id, self.cell):
            # A mistyped cell would otherwise look live and show nothing to stop.
            await self._refuse(f"There is no cell {self.cell!r} in this organisation.", NOT_FOUND)
            return
        MEMBERSHIPS.watch(self)
        self.groups_joined = [
            groups.organisation_group(access.organisation_id),
            groups.user_group(access.user_id),
            groups.cell_group(access.organisation_id, self.cell),
        ]
        for group in self.groups_joined:
            await self.channel_layer.group_add(group, self.channel_name)
        await self._send_snapshot()

    async def disconnect(self, code: int) -> None:
        MEMBERSHIPS.forget(self)
        if self._state_flush is not None:
            self._state_flush.cancel()
        for group in self.groups_joined:
            await self.channel_layer.group_discard(group, self.channel_name)

    async def receive_json(self, content: Any, **kwargs: Any) -> None:
        """The client asks for one thing: a new snapshot, after a hole in a case's numbers."""
        if isinstance(content, dict) and content.get("type") == "resync" and self.access:
            await self._send_snapshot()

    # The channel layer's messages -------------------------------------------------------

    async def live_events(self, message: dict[str, Any]) -> None:
        """The deltas of one commit: those for this socket's cell go out now, in one frame (the
        sender's own encoding when none was left out); cobot states wait (on_cobot_state)."""
        events = message["events"]
        if not self._organisation_matches(message):
            return
        forwarded = []
        for event, cell in zip(events, message["cells"], strict=True):
            kind = event.get("type")
            if not self._cell_matches(cell, event):
                continue
            if kind == "cobot-state":
                self.on_cobot_state(event)
            elif kind in PASSED_ON:
                forwarded.append(event)
        if len(forwarded) == len(events):
            await self.send(text_data=message["text"])
        elif forwarded:
            await self.send_json(forwarded)

    async def membership_ended(self, message: dict[str, Any]) -> None:
        """An admin ended the user's membership (groups.membership_ended_on_commit)."""
        if self._organisation_matches(message):
            await self.revoke()

    def on_cobot_state(self, event: LiveEvent) -> None:
        """Kept: the latest state per cobot goes out at most every STATE_INTERVAL."""
        for state in event["states"]:  # type: ignore[typeddict-item]
            self._states[state["cobot"]] = state
        if self._state_flush is None:
            wait = max(0.0, self._last_state_frame + STATE_INTERVAL - time.monotonic())
            self._state_flush = asyncio.get_running_loop().call_later(
                wait, lambda: asyncio.ensure_future(self._flush_states())
            )

    # Helpers ------------------------------------------------------------------------------

    async def _flush_states(self) -> None:
        self._state_flush = None
        states, self._states = list(self._states.values()), {}
        if states and self.access is not None:
            self._last_state_frame = time.monotonic()
            await self.send_json({"type": "cobot-state", "states": states})

    def _organisation_matches(self, message: dict[str, Any]) -> bool:
        """The socket's user is (as of the last membership check) a member of the message's
        organisation; checked before every send."""
        access = self.access
        return access is not None and message.get("organisation") == access.organisation_id

    def _cell_matches(self, cell: str, event: LiveEvent) -> bool:
        """A cobot's deltas reach its cell's tablets and the whole floor's; the rest every tablet."""
        return event["type"] not in CELL_SCOPED or not self.cell or cell == self.cell

    async def revoke(self) -> None:
        """The membership is gone (Memberships found it): nothing more is sent."""
        if self.access is not None:
            await self._refuse("You are no longer a member of this organisation.", FORBIDDEN)

    async def _send_snapshot(self) -> None:
        assert self.access is not None
        snapshot = await database_sync_to_async(selectors.snapshot)(self.access, self.cell)
        await self.send_json(snapshot)

    async def _refuse(self, reason: str, code: int) -> None:
        self.access = None
        await self.send_json({"type": "refused", "reason": reason})
        await self.close(code=code)


class Memberships:
    """The process's sockets and their memberships, read again every RECHECK_SECONDS in one query."""

    def __init__(self) -> None:
        self.sockets: set[TabletConsumer] = set()
        self.task: asyncio.Task[None] | None = None

    def watch(self, socket: TabletConsumer) -> None:
        self.sockets.add(socket)
        if self.task is None or self.task.done():
            self.task = asyncio.get_running_loop().create_task(self._recheck_forever())

    def forget(self, socket: TabletConsumer) -> None:
        self.sockets.discard(socket)

    async def _recheck_forever(self) -> None:
        while self.sockets:
            await asyncio.sleep(RECHECK_SECONDS)
            await self.recheck()

    async def recheck(self) -> None:
        watched = [s for s in self.sockets if s.access is not None]
        if not watched:
            return
        pairs = {(s.access.user_id, s.access.organisation_id) for s in watched}  # type: ignore[union-attr]
        valid = await database_sync_to_async(selectors.valid_memberships)(pairs)
        for socket in watched:
            access = socket.access
            if access is not None and (access.user_id, access.organisation_id) not in valid:
                await socket.revoke()


MEMBERSHIPS = Memberships()


def _parameters(query_string: bytes) -> tuple[int | None, str]:
    """(organisation id or None, cell) from the query string; ValueError naming what is wrong."""
    query = parse_qs(query_string.decode("latin-1"))
    raw = (query.get("organisation") or [""])[0]
    if raw and not (raw.isascii() and raw.isdigit()):
        raise ValueError(f"organisation must be an id (a whole number), not {raw!r}.")
    cell = (query.get("cell") or [""])[0]
    try:
        validate_cell(cell)
    except Exception:
        raise ValueError(f"{cell!r} is not a cell name.") from None
    return (int(raw) if raw else None), cell
