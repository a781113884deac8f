"""A space constraint's interruption, on the cobot: pause (or slow) it, and resume it after.

The rows (who interrupted whom, when it ended) are written by the case
services; these commands follow on the workers, each sent by one sender only,
and what the cobot refused is kept on the interruption for the sweeper.
"""

from __future__ import annotations

import threading
from collections import defaultdict
from collections.abc import Iterator
from contextlib import contextmanager

from django.conf import settings
from django.db import connection, transaction
from django.utils import timezone

from hrc.cases import dispatch
from hrc.cases.choices import JobState
from hrc.cases.models import Interruption, Job
from hrc.cobots.drivers.base import DriverError
from hrc.cobots.drivers.runner import driver_for_cobot
from hrc_gateway import urua

SLOW_OVERRIDE_PERCENT = 10.0
FULL_OVERRIDE_PERCENT = 100.0


def _locked_interruption(interruption_id: int) -> Interruption:
    return (
        Interruption.objects.select_for_update(of=("self",))
        .select_related("cobot")
        .get(pk=interruption_id)
    )


# The embedded default's senders of one interruption's commands, all threads of one process.
_embedded_senders: defaultdict[int, threading.Lock] = defaultdict(threading.Lock)


@contextmanager
def _sole_sender(interruption_id: int) -> Iterator[Interruption]:
    """The interruption, read by the only thread that may command its cobot for it until exit.

    On PostgreSQL its row lock, held across the cobot call, blocks only that row. The
    embedded SQLite has one write lock for the whole database, taken at BEGIN: held
    across a call to an unreachable cobot it would stall every writer for the connect
    timeout. There (no Redis: one process) a lock per interruption serialises the
    senders instead, and each write is a short transaction of its own.
    """
    if connection.vendor == "sqlite" and not settings.REDIS_URL:
        with _embedded_senders[interruption_id]:
            yield Interruption.objects.select_related("cobot").get(pk=interruption_id)
        return
    with transaction.atomic():
        yield _locked_interruption(interruption_id)


def _command(interruption: Interruption, *, pause: bool) -> bool:
    """Pauses or resumes (slows or restores the speed of) the cobot; records why when it cannot."""
    driver = driver_for_cobot(interruption.cobot)
    try:
        if interruption.mode == "slow":
            speed = SLOW_OVERRIDE_PERCENT if pause else FULL_OVERRIDE_PERCENT
            driver.write({urua.STATE_OVERRIDE: speed})
        else:
            driver.call("PauseProgram" if pause else "StartProgram")
    except DriverError as error:
        interruption.error = f"{'pause' if pause else 'resume'}: {error}"
        interruption.save(update_fields=["error"])
        return False
    return True


def interrupt_cobot(interruption_id: int) -> None:
    """Pauses (or slows) the cobot for an interruption still open; never twice."""
    with _sole_sender(interruption_id) as interruption:
        if interruption.ended_at is not None or interruption.paused_at is not None:
            return
        if _command(interruption, pause=True):
            interruption.paused_at = timezone.now()
            interruption.save(update_fields=["paused_at"])


def resume_cobot(interruption_id: int) -> None:
    """Resumes the cobot after an interruption that paused it, when no other keeps it paused.

    A resume that fails is left for the sweeper, which sends it again until it succeeds.
    """
    with _sole_sender(interruption_id) as interruption:
        if interruption.ended_at is None or interruption.resumed_at is not None:
            return
        others = Interruption.objects.filter(
            cobot=interruption.cobot, ended_at__isnull=True, paused_at__isnull=False
        ).exclude(pk=interruption.pk)
        needed = interruption.paused_at is not None and not others.exists()
        needed = needed and interruption.cobot.stopped_at is None  # a STOP's resume restarts it
        if needed and not _command(interruption, pause=False):
            return
        interruption.resumed_at = timezone.now()
        interruption.save(update_fields=["resumed_at"])
    # The cobot's queue waited for this interruption to settle.
    job_id = (
        Job.objects.filter(cobot=interruption.cobot, state=JobState.QUEUED)
        .values_list("pk", flat=True)
        .first()
    )
    if job_id is not None:
        with transaction.atomic():
            dispatch.send_on_commit("run_job", job_id)


def to_redo() -> list[tuple[str, int]]:
    """Pauses that failed while the interruption is open, resumes not yet done after it ended."""
    pauses = Interruption.objects.filter(ended_at__isnull=True, paused_at__isnull=True).exclude(
        error=""
    )
    resumes = Interruption.objects.filter(ended_at__isnull=False, resumed_at__isnull=True)
    return [("interrupt_cobot", pk) for pk in pauses.values_list("pk", flat=True)] + [
        ("resume_cobot", pk) for pk in resumes.values_list("pk", flat=True)
    ]
