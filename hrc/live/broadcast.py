"""The one way anything reaches the tablets: after the transaction commits, through the channel layer.

`send_event_on_commit` is the helper (Zulip's `send_event_on_commit`); the
case services call `case_event_on_commit` from `record_event`, the jobs
call `cobot_queue_on_commit` where a cobot's queue changes without a case
event. Both build their payload from the objects the caller already holds,
so the hot path pays no query: the commit hook only puts the payload on an
in-process queue. One sender thread per process drains that queue in order
and does the group_send (its Redis round trips never delay the step that
caused them), reading the cobot queues that changed once per batch.

Groups: `hrc.org.<organisation>` (every delta from the database: cases,
work items, incidents, cobot queues, STOPs), `hrc.user.<user>`,
`hrc.cell.<organisation>` (the gateways' cobot states for tablets of the
whole floor) and `hrc.cell.<organisation>.<cell>` (those of one cell's
cobots). A channel message is {"type": "live.events", "organisation": id,
"events": [<hrc.live.events.LiveEvent>, …], "cells": the cell of each event's
cobot ("" when it is no cobot's), "text": the events as a JSON array}. The
sender puts what one batch holds for the same groups (a commit's deltas and
the queues it changed) in one message, encoded once: 200 tablets cost 200
frames per commit, not 200 frames and JSON encodings per delta. The
consumer re-checks each message against the socket's user before sending.

A worker `hold`s the sender while it takes a job, until the cobot has
accepted the step: the sender's work (a query, JSON, Redis) would otherwise
compete for the process's GIL with the write that moves the cobot. A hold
delays the tablets by HOLD_LIMIT at most.
"""

from __future__ import annotations

import asyncio
import atexit
import json
import logging
import os
import queue
import threading
import time
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from channels.layers import get_channel_layer
from django.db import connections, transaction

from hrc.live.events import CaseData, CobotStateData, IncidentData, LiveEvent, WorkItemData

if TYPE_CHECKING:
    from django.contrib.auth.models import User

    from hrc.cases.models import Case, WorkItem

logger = logging.getLogger(__name__)

CHANNEL_MESSAGE_TYPE = "live.events"
# To a user's sockets: their membership of the message's organisation ended.
MEMBERSHIP_ENDED_TYPE = "membership.ended"
# How long flush() waits for the sender by default.
FLUSH_TIMEOUT = 10.0
# The sender keeps its database connection (for the cobot queues) while it is busy.
IDLE_SECONDS = 2.0
# The longest a hold keeps the sender waiting, released or not.
HOLD_LIMIT = 0.2

_INCIDENT_EVENTS = frozenset({"incident-opened", "incident-resolved"})
_CLOSED_ITEM_STATES = frozenset({"completed", "withdrawn"})


# Group names ---------------------------------------------------------------------------


def organisation_group(organisation_id: int) -> str:
    return f"hrc.org.{organisation_id}"


def user_group(user_id: int) -> str:
    return f"hrc.user.{user_id}"


def cell_groups(organisation_id: int, cell: str) -> list[str]:
    """Where a cobot's deltas go: the whole floor's tablets, and its cell's when it has one."""
    floor = f"hrc.cell.{organisation_id}"
    return [floor, f"{floor}.{cell}"] if cell else [floor]


def cell_group(organisation_id: int, cell: str) -> str:
    """The group a tablet of `cell` ("" for the whole floor) joins."""
    return cell_groups(organisation_id, cell)[-1]


# The helper ----------------------------------------------------------------------------


def send_event_on_commit(
    groups: Iterable[str], event: LiveEvent, *, organisation: int, cell: str = ""
) -> None:
    """Sends `event` to `groups` once the transaction commits; nothing when it rolls back.

    `organisation` and `cell` say whose it is: the consumer checks them against
    the socket before sending. Outside a transaction it is sent at once.
    """
    send = _Send(list(groups), organisation, [event], [cell])
    transaction.on_commit(lambda: _sender().put(send))


def membership_ended_on_commit(user_id: int, organisation_id: int) -> None:
    """Closes, after commit, the user's sockets on the organisation: at once, not on the
    consumers' next membership check."""
    transaction.on_commit(lambda: _sender().put(_MembershipEnded(user_id, organisation_id)))


def cobot_queue_on_commit(cobot_id: int) -> None:
    """Says, after commit, that the cobot's queue changed; the sender reads it and sends it."""
    transaction.on_commit(lambda: _sender().put(_QueueChanged(cobot_id)))


def case_event_on_commit(
    case: Case,
    event: str,
    item: WorkItem | None,
    user: User | None,
    detail: Mapping[str, Any] | None,
) -> None:
    """The delta for a case event just recorded (case.last_seq is its number). No query.

    Call from record_event, while holding the case row lock.
    """
    seq = case.last_seq
    delta: LiveEvent
    if event in _INCIDENT_EVENTS:
        delta = {
            "type": "incident", "case": case.pk, "seq": seq, "event": event,
            "incident": incident_data(case, item, dict(detail or {})),
        }  # fmt: skip
    elif item is not None:
        delta = {
            "type": "work-item", "case": case.pk, "seq": seq, "event": event,
            "item": work_item_data(case, item, started_by=user if event == "task-started" else None),
        }  # fmt: skip
    else:
        delta = {
            "type": "case",
            "case": case.pk,
            "seq": seq,
            "event": event,
            "data": case_data(case),
        }
    send_event_on_commit(
        [organisation_group(case.organisation_id)], delta, organisation=case.organisation_id
    )
    if item is not None and item.cobot_id is not None and item.kind != "operator":
        cobot_queue_on_commit(item.cobot_id)


async def send_cobot_state(state: CobotStateData, *, organisation: int, cell: str) -> None:
    """Sends a cobot's gateway state now (the monitor's; no transaction is involved)."""
    event: LiveEvent = {"type": "cobot-state", "states": [state]}
    await _group_send_all([_Send(cell_groups(organisation, cell), organisation, [event], [cell])])


# Payloads from objects in hand ---------------------------------------------------------


def case_data(case: Case) -> CaseData:
    return {
        "id": case.pk,
        "seq": case.last_seq,
        "status": case.status,
        "name": _case_name(case),
        "cobots": cobots_of_mapping(case.actor_mapping),
    }


def _case_name(case: Case) -> str:
    # Only when the version is loaded already (lock_case reads it along): never a query here.
    from hrc.cases.models import Case as CaseModel

    if not CaseModel.version.is_cached(case):
        return ""
    return str((case.version.document or {}).get("name") or "")


def cobots_of_mapping(mapping: Mapping[str, Any] | None) -> list[int]:
    """The cobots a case's actor mapping names, in id order."""
    return sorted(
        {
            int(binding["cobot"])
            for binding in (mapping or {}).values()
            if isinstance(binding, Mapping) and binding.get("cobot") is not None
        }
    )


def candidates_of(mapping: Mapping[str, Any] | None, actor: str) -> list[int]:
    """The users an operator actor is mapped to (the rule services._offer uses)."""
    binding = (mapping or {}).get(actor)
    if not isinstance(binding, Mapping):
        return []
    return sorted(int(user) for user in binding.get("users") or ())


def work_item_data(case: Case, item: WorkItem, *, started_by: User | None = None) -> WorkItemData:
    claimed_by = item.claimed_by_id
    if claimed_by is None and started_by is not None and item.kind == "operator":
        claimed_by = started_by.pk  # starting claims it; the service sets it after the event
    return {
        "id": item.pk,
        "case": item.case_id,
        "task": item.task,
        "label": item.label,
        "actor": item.actor,
        "kind": item.kind,
        "state": item.state,
        "instructions": item.instructions,
        "team": item.team_id,
        "cobot": item.cobot_id,
        "candidates": candidates_of(case.actor_mapping, item.actor)
        if item.kind == "operator"
        else [],
        "claimed_by": claimed_by,
        "offered_at": item.offered_at.isoformat(),
        "started_at": item.started_at.isoformat() if item.started_at else None,
    }


def incident_data(case: Case, item: WorkItem | None, detail: dict[str, Any]) -> IncidentData:
    return {
        "id": int(detail.get("incident") or 0),
        "case": case.pk,
        "work_item": item.pk if item is not None else None,
        "kind": str(detail.get("kind") or ""),
        "message": str(detail.get("message") or ""),
        "resolution": str(detail.get("resolution") or ""),
    }


# The sender ----------------------------------------------------------------------------


@dataclass
class _Send:
    groups: list[str]
    organisation: int
    events: list[LiveEvent]
    cells: list[str]  # the cell of each event's cobot, "" for the rest

    def message(self) -> dict[str, Any]:
        return {
            "type": CHANNEL_MESSAGE_TYPE,
            "organisation": self.organisation,
            "events": self.events,
            "cells": self.cells,
            "text": json.dumps(self.events, separators=(",", ":")),
        }


@dataclass
class _QueueChanged:
    cobot_id: int


@dataclass
class _MembershipEnded:
    user_id: int
    organisation: int


@dataclass
class _Flush:
    done: threading.Event = field(default_factory=threading.Event)


_Work = _Send | _QueueChanged | _MembershipEnded | _Flush


class _Sender:
    """One daemon thread per process that sends what the commit hooks queued, in order."""

    def __init__(self) -> None:
        self.queue: queue.SimpleQueue[_Work] = queue.SimpleQueue()
        self.pid = os.getpid()
        self.holds = 0
        self.open = threading.Event()  # set while nothing holds the sender
        self.open.set()
        self.guard = threading.Lock()
        self.thread = threading.Thread(target=self._run, name="hrc-live-sender", daemon=True)
        self.thread.start()

    def put(self, work: _Work) -> None:
        self.queue.put(work)

    def hold(self) -> Hold:
        with self.guard:
            self.holds += 1
            self.open.clear()
        return Hold(self)

    def _run(self) -> None:
        loop = asyncio.new_event_loop()
        while True:
            try:
                batch = [self.queue.get(timeout=IDLE_SECONDS)]
            except queue.Empty:
                # Idle: give the queue reads' connection back (it would keep the database busy).
                connections.close_all()
                continue
            self.open.wait(HOLD_LIMIT)
            while True:  # whatever else is waiting goes in the same batch
                try:
                    batch.append(self.queue.get_nowait())
                except queue.Empty:
                    break
            try:
                self._send_batch(batch, loop)
            except Exception:
                logger.exception("Live broadcast failed; tablets resynchronise on their next delta")
            if any(isinstance(work, _Flush) for work in batch):
                connections.close_all()  # whoever waits may be about to drop the database
            for work in batch:
                if isinstance(work, _Flush):
                    work.done.set()

    def _send_batch(self, batch: list[_Work], loop: asyncio.AbstractEventLoop) -> None:
        sends = [work for work in batch if isinstance(work, _Send)]
        # The queues the batch changed go in the same frame as its deltas, after them.
        changed = list(dict.fromkeys(w.cobot_id for w in batch if isinstance(w, _QueueChanged)))
        if changed:
            sends += _queue_sends(changed)
        if sends:
            _run_on_layer(_group_send_all(sends), loop)
        ended = [work for work in batch if isinstance(work, _MembershipEnded)]
        if ended:
            _run_on_layer(_send_membership_ended(ended), loop)


def _queue_sends(cobot_ids: list[int]) -> list[_Send]:
    from hrc.live.selectors import cobot_queues

    return [
        _Send([organisation_group(organisation)], organisation,
              [{"type": "cobot-queue", "queue": data}], [cell])
        for organisation, cell, data in cobot_queues(cobot_ids)
    ]  # fmt: skip


async def _group_send_all(sends: list[_Send]) -> None:
    layer = get_channel_layer()
    if layer is None:
        return
    for send in _merged(sends):
        message = send.message()
        for group in send.groups:
            await layer.group_send(group, message)


async def _send_membership_ended(ended: list[_MembershipEnded]) -> None:
    layer = get_channel_layer()
    if layer is None:
        return
    for work in ended:
        message = {"type": MEMBERSHIP_ENDED_TYPE, "organisation": work.organisation}
        await layer.group_send(user_group(work.user_id), message)


def _merged(sends: list[_Send]) -> list[_Send]:
    """The sends to the same groups of the same organisation as one, in order."""
    merged: dict[tuple[tuple[str, ...], int], _Send] = {}
    for send in sends:
        key = (tuple(send.groups), send.organisation)
        found = merged.get(key)
        if found is None:
            merged[key] = _Send(send.groups, send.organisation, list(send.events), list(send.cells))
        else:
            found.events += send.events
            found.cells += send.cells
    return list(merged.values())


# The ASGI server's loop, when this process serves tablets: the in-memory channel
# layer (the embedded demo) only works from the loop its consumers run on.
server_loop: asyncio.AbstractEventLoop | None = None


def _run_on_layer(coroutine: Any, own_loop: asyncio.AbstractEventLoop) -> None:
    target = server_loop
    if target is not None and target.is_running():
        asyncio.run_coroutine_threadsafe(coroutine, target).result(FLUSH_TIMEOUT)
    else:
        own_loop.run_until_complete(coroutine)


class Hold:
    """Keeps this process's sender from starting a batch until released (see the module's doc)."""

    def __init__(self, sender: _Sender) -> None:
        self._sender = sender
        self._released = False

    def release(self) -> None:
        """Lets the sender go on; any number of calls, from any thread."""
        sender = self._sender
        with sender.guard:
            if self._released:
                return
            self._released = True
            sender.holds -= 1
            if sender.holds == 0:
                sender.open.set()


def hold() -> Hold:
    return _sender().hold()


_lock = threading.Lock()
_current: _Sender | None = None


def _sender() -> _Sender:
    """This process's sender, started on first use (again in a forked child)."""
    global _current
    with _lock:
        if _current is None or _current.pid != os.getpid():
            _current = _Sender()
        return _current


def flush(timeout: float = FLUSH_TIMEOUT) -> bool:
    """Waits until everything queued so far has been sent; False when the sender did not finish."""
    marker = _Flush()
    _sender().put(marker)
    return marker.done.wait(timeout)


@atexit.register
def _flush_at_exit() -> None:
    # A command that ends right after a commit would otherwise lose its last deltas.
    if _current is not None and _current.pid == os.getpid():
        _current.put(marker := _Flush())
        marker.done.wait(2.0)


def now() -> float:
    return time.time()
