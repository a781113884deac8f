"""The sender thread: what the commit hooks queued goes out in order, in batches (private to live).

Use hrc.live.groups. One daemon thread per process drains the queue and does
the group_send, so its Redis round trips never delay the step that caused
them; it reads the cobot queues that changed once per batch, and a cobot's
at most once per QUEUE_COALESCE_SECONDS (QueueReads). Under load a batch goes
at most every BATCH_SECONDS, gathering what comes meanwhile. What one batch
holds for the same groups goes in one channel message, encoded once: 200
tablets cost 200 frames per commit, not 200 encodings per delta.

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
from collections.abc import Callable, Coroutine
from dataclasses import dataclass, field
from typing import Any

from channels.layers import get_channel_layer
from django.db import connections

from hrc.live.events import LiveEvent

logger = logging.getLogger(__name__)

# The channel message of a batch of deltas: {"type", "organisation", "events", "cells", "text"}.
CHANNEL_MESSAGE_TYPE = "live.events"
# To a user's sockets: their membership of the message's organisation ended.
MEMBERSHIP_ENDED_TYPE = "membership.ended"
# How long flush() waits for the sender by default.
FLUSH_TIMEOUT = 10.0
# The sender keeps its database connection (for the cobot queues) while it is busy.
IDLE_SECONDS = 2.0
# The longest a hold keeps the sender waiting, released or not.
HOLD_LIMIT = 0.2
# A cobot's queue is read and sent at most once in this many seconds per process: a lease and
# its finish, close together, cost one read (the tablets see the queue this much later at most).
QUEUE_COALESCE_SECONDS = 0.05
# Under load, batches go at most this often per process: what arrives meanwhile joins the
# next one, so a busy worker pays one channel send per batch, not one per step. A sender that
# sent nothing for this long sends at once.
BATCH_SECONDS = 0.025


@dataclass
class Send:
    """Events for groups; `cells` names the cell of each event's cobot ("" for the rest)."""

    groups: list[str]
    organisation: int
    events: list[LiveEvent]
    cells: list[str]

    def message(self) -> dict[str, Any]:
        return {
            "type": CHANNEL_MESSAGE_TYPE,
            "organisation": self.organisation,
            "events": self.events,
            "cells": self.cells,
            "text": json.dumps(self.events, separators=(",", ":")),
        }


@dataclass
class QueueChanged:
    cobot_id: int


@dataclass
class MembershipEnded:
    user_group: str
    organisation: int


@dataclass
class _Flush:
    done: threading.Event = field(default_factory=threading.Event)


Work = Send | QueueChanged | MembershipEnded | _Flush
# The sends that tell the tablets the current queues of these cobots (one read per batch).
QueueReader = Callable[[list[int]], list[Send]]


class QueueReads:
    """Which changed cobot queues to read now: a cobot read less than QUEUE_COALESCE_SECONDS ago
    waits for the window's end, and all its changes meanwhile cost that one read."""

    def __init__(self) -> None:
        self.last_read: dict[int, float] = {}
        self.deferred: dict[int, float] = {}  # cobot → when its window ends

    def due(self, changed: list[int], now: float, *, everything: bool = False) -> list[int]:
        """The cobots to read now, from those `changed` and those deferred before;
        `everything` reads all of them (a flush). Marks them read at `now`."""
        window = QUEUE_COALESCE_SECONDS
        for cobot in changed:
            if cobot not in self.deferred:
                self.deferred[cobot] = self.last_read.get(cobot, -window) + window
        ready = [c for c, at in self.deferred.items() if everything or at <= now]
        for cobot in ready:
            del self.deferred[cobot]
            self.last_read[cobot] = now
        return ready

    def wait(self, now: float) -> float | None:
        """Seconds until the next deferred read is due; None when none is."""
        if not self.deferred:
            return None
        return max(0.0, min(self.deferred.values()) - now)


class Sender:
    """One daemon thread per process that sends what the commit hooks queued, in order."""

    def __init__(self, read_queues: QueueReader) -> None:
        self.read_queues = read_queues
        self.queue_reads = QueueReads()
        self.queue: queue.SimpleQueue[Work] = queue.SimpleQueue()
        self.pid = os.getpid()
        self.holds = 0
        self.open = threading.Event()  # set while nothing holds the sender
        self.open.set()
        self.guard = threading.Lock()
        self.thread = threading.Thread(target=self._run, name="hrc-live-sender", daemon=True)
        self.thread.start()

    def put(self, work: Work) -> None:
        self.queue.put(work)

    def hold(self) -> Hold:
        with self.guard:
            self.holds += 1
            self.open.clear()
        return Hold(self)

    def flush(self, timeout: float) -> bool:
        """Waits until everything queued so far has been sent; False when it did not finish."""
        marker = _Flush()
        self.put(marker)
        return marker.done.wait(timeout)

    def _run(self) -> None:
        loop = asyncio.new_event_loop()
        sent_at = -BATCH_SECONDS
        while True:
            deferred = self.queue_reads.wait(time.monotonic())
            try:
                batch = [self.queue.get(timeout=IDLE_SECONDS if deferred is None else deferred)]
            except queue.Empty:
                if deferred is None:
                    # Idle: give the queue reads' connection back (it would keep the database busy).
                    connections.close_all()
                    continue
                batch = []  # a deferred queue read is due
            self.open.wait(HOLD_LIMIT)
            time.sleep(max(sent_at + BATCH_SECONDS - time.monotonic(), 0.0))
            while True:  # whatever else is waiting goes in the same batch
                try:
                    batch.append(self.queue.get_nowait())
                except queue.Empty:
                    break
            flushed = [work for work in batch if isinstance(work, _Flush)]
            sent_at = time.monotonic()
            try:
                self._send_batch(batch, loop, everything=bool(flushed))
            except Exception:
                logger.exception("Live broadcast failed; tablets resynchronise on their next delta")
            if flushed:
                connections.close_all()  # whoever waits may be about to drop the database
            for work in flushed:
                work.done.set()

    def _send_batch(
        self, batch: list[Work], loop: asyncio.AbstractEventLoop, *, everything: bool
    ) -> None:
        """Sends the batch's deltas, then the queues due (`everything`: all changed so far)."""
        sends = [work for work in batch if isinstance(work, Send)]
        # The queues due (those the batch changed, unless read within the window) go in the
        # same frame as its deltas, after them.
        changed = list(dict.fromkeys(w.cobot_id for w in batch if isinstance(w, QueueChanged)))
        due = self.queue_reads.due(changed, time.monotonic(), everything=everything)
        if due:
            sends += self.read_queues(due)
        if sends:
            run_on_layer(group_send_all(sends), loop)
        ended = [work for work in batch if isinstance(work, MembershipEnded)]
        if ended:
            run_on_layer(_send_membership_ended(ended), loop)


async def group_send_all(sends: list[Send]) -> None:
    layer = get_channel_layer()
    if layer is None:
        return
    for send in _merged(sends):
        message = send.message()
        for group in send.groups:
            await layer.group_send(group, message)


async def _send_membership_ended(ended: list[MembershipEnded]) -> None:
    layer = get_channel_layer()
    if layer is None:
        return
    for work in ended:
        message = {"type": MEMBERSHIP_ENDED_TYPE, "organisation": work.organisation}
        await layer.group_send(work.user_group, message)


def _merged(sends: list[Send]) -> list[Send]:
    """The sends to the same groups of the same organisation as one, in order."""
    merged: dict[tuple[tuple[str, ...], int], Send] = {}
    for send in sends:
        key = (tuple(send.groups), send.organisation)
        found = merged.get(key)
        if found is None:
            merged[key] = Send(send.groups, send.organisation, list(send.events), list(send.cells))
        else:
            found.events += send.events
            found.cells += send.cells
    return list(merged.values())


# The ASGI server's loop, when this process serves tablets: the in-memory channel
# layer (the embedded demo) only works from the loop its consumers run on.
server_loop: asyncio.AbstractEventLoop | None = None


def run_on_layer(coroutine: Coroutine[Any, Any, None], own_loop: asyncio.AbstractEventLoop) -> None:
    target = server_loop
    if target is not None and target.is_running():
        asyncio.run_coroutine_threadsafe(coroutine, target).result(FLUSH_TIMEOUT)
    else:
        own_loop.run_until_complete(coroutine)


class Hold:
    """Keeps this process's sender from starting a batch until released (see the module's doc)."""

    def __init__(self, sender: Sender) -> None:
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


_lock = threading.Lock()
_current: Sender | None = None


def current(read_queues: QueueReader) -> Sender:
    """This process's sender, started on first use (again in a forked child)."""
    global _current
    with _lock:
        if _current is None or _current.pid != os.getpid():
            _current = Sender(read_queues)
        return _current


@atexit.register
def _flush_at_exit() -> None:
    # A command that ends right after a commit would otherwise lose its last deltas.
    if _current is not None and _current.pid == os.getpid():
        _current.flush(2.0)
