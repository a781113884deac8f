"""How much CPU a request may spend in the engine, and how many such requests run at once.

A 20 KB pattern can have millions of reachable markings, and six checks of
one at once took every core of the web server. The shape that bounds it:

- A check in a request (`check`, `check-document`) decides soundness within
  the interactive budget (HRC_CHECK_SECONDS, HRC_CHECK_MARKINGS): the editor
  asks on every change, and "too large to decide in 2 s" is an answer it shows.
- Publishing decides within the larger publish budget, because its report is
  the record cases run against; an engineer publishes rarely and waits for it.
- Every request that hands a document to the engine (check, check-document,
  layout, execution-net, publish, import) first takes one of its
  organisation's HRC_ENGINE_SLOTS slots, and is refused at once with a 429
  (and Retry-After) when all are taken: one organisation can keep at most
  that many cores busy, whichever processes serve it, and waiting requests do
  not pile up on the server's threads. Only engineers and admins reach these
  actions (the views' permissions).

The slots are PostgreSQL session advisory locks: they hold across daphne's
processes and Celery's workers, cost no table, and a crashed process's locks
go with its connection. The embedded SQLite default runs in one process, so
there a semaphore per organisation does the same.

Checks run in the engine's worker processes (hrc.patterns.engine_workers),
not on the server's threads. Not Celery: the editor waits for the report in
its request, and a result channel (a row to poll) would add a round trip to
every check for what a pipe gives at once.
"""

import threading
from collections import defaultdict
from collections.abc import Iterator
from contextlib import contextmanager

from django.conf import settings
from django.db import DatabaseError, connection

from hrc.engine.budget import Budget
from hrc.errors import Busy
from hrc.patterns.documents import Report
from hrc.patterns.engine_workers import check_in_worker

# High bits of every slot's advisory lock key, so the slots collide with no other
# advisory lock: the key is this, the slot number and the organisation's id.
_LOCK_SPACE = 0x4852 << 40


class EngineBusy(Busy):
    """All of the organisation's engine slots are taken; try again in a few seconds (429)."""

    code = "engine-busy"

    def __init__(self, slots: int) -> None:
        super().__init__(
            f"Your organisation already runs {slots} checks, layouts or imports at once, "
            "the most it may: try again in a few seconds.",
            retry_after=max(1, round(settings.HRC_CHECK_SECONDS)),
        )


def interactive_budget() -> Budget:
    """The budget of a check that someone waits for in the editor."""
    return Budget(max_markings=settings.HRC_CHECK_MARKINGS, seconds=settings.HRC_CHECK_SECONDS)


def publish_budget() -> Budget:
    """The budget of the check that decides whether a draft may be published."""
    return Budget(
        max_markings=settings.HRC_PUBLISH_CHECK_MARKINGS,
        seconds=settings.HRC_PUBLISH_CHECK_SECONDS,
    )


def checked(document: object, budget: Budget) -> Report:
    """The engine's check of `document` within `budget`, computed in an engine worker
    (hrc.patterns.engine_workers)."""
    return check_in_worker(document, budget)


@contextmanager
def engine_slot(organisation_id: int) -> Iterator[None]:
    """Holds one of the organisation's engine slots while the block runs; raises EngineBusy."""
    slots = settings.HRC_ENGINE_SLOTS
    if connection.vendor != "postgresql":
        with _embedded_slot(organisation_id, slots):
            yield
        return
    key = _advisory_slot(organisation_id, slots)
    try:
        yield
    finally:
        _release(key)


def _advisory_slot(organisation_id: int, slots: int) -> int:
    """The key of the first free slot, now locked by this session; raises EngineBusy."""
    with connection.cursor() as cursor:
        for slot in range(slots):
            key = _LOCK_SPACE + (slot << 32) + organisation_id
            cursor.execute("SELECT pg_try_advisory_lock(%s)", [key])
            row = cursor.fetchone()
            if row is not None and row[0]:
                return key
    raise EngineBusy(slots)


def _release(key: int) -> None:
    try:
        with connection.cursor() as cursor:
            cursor.execute("SELECT pg_advisory_unlock(%s)", [key])
    except DatabaseError:
        # The block failed inside a transaction, which now refuses every statement:
        # ending the session frees its locks (the pool opens a new one).
        connection.close()


_embedded_guard = threading.Lock()
_embedded_in_use: defaultdict[int, int] = defaultdict(int)


@contextmanager
def _embedded_slot(organisation_id: int, slots: int) -> Iterator[None]:
    with _embedded_guard:
        if _embedded_in_use[organisation_id] >= slots:
            raise EngineBusy(slots)
        _embedded_in_use[organisation_id] += 1
    try:
        yield
    finally:
        with _embedded_guard:
            _embedded_in_use[organisation_id] -= 1
