"""A space constraint's interruption, on the cobot: pause (or slow) it, and resume it after.

A wait or a refusal (a task kept out of the area) commands nothing; only pauses
and slowdowns go to the cobot. The speed a step runs at is set by its own worker
before the step is sent (`set_speed_before_step`): slowed when it starts beside
an operator under "slow", full speed when a slowdown has ended meanwhile.

The rows (who interrupted whom, when it ended) are written by the case
services; these commands follow on the workers. Each command is claimed in a
committed conditional update (Interruption.claimed_at), sent outside any
transaction (hrc.cobots.commands), and its outcome recorded in a short
transaction: it is never sent twice, no lock waits on the robot, and what the
cobot refused is kept on the interruption for the sweeper to send again.
"""

from __future__ import annotations

import datetime as dt
from typing import Final

from django.db import transaction
from django.db.models import Q
from django.utils import timezone

from hrc.cases import dispatch, progress
from hrc.cases.choices import COMMANDED_MODES, JobState
from hrc.cases.dispatch import Task
from hrc.cases.models import Interruption, Job
from hrc.cobots.commands import outside_transaction
from hrc.cobots.drivers.base import DriverError
from hrc.cobots.drivers.runner import driver_for_cobot
from hrc.cobots.models import Cobot
from hrc_gateway import urua

SLOW_OVERRIDE_PERCENT = 10.0
FULL_OVERRIDE_PERCENT = 100.0
# A claim this old died with its sender (a cobot answers or times out well before): free again.
CLAIM_EXPIRES: Final = dt.timedelta(minutes=2)


def interrupt_cobot(interruption_id: int) -> None:
    """Pauses (or slows) the cobot for an interruption still open; never twice."""
    won = _claim(interruption_id, Q(ended_at__isnull=True, paused_at__isnull=True))
    if won is None:
        return
    claimed, cobot = won
    error = _command(claimed, cobot, pause=True)
    with transaction.atomic():
        if error:
            _record(claimed, error=f"pause: {error}")
            return
        _record(claimed, paused_at=timezone.now())
        if Interruption.objects.filter(pk=claimed.pk, ended_at__isnull=False).exists():
            # It ended while the pause was on its way: that resume found the claim taken.
            dispatch.send_on_commit(Task.RESUME_COBOT, claimed.pk)


def resume_cobot(interruption_id: int) -> None:
    """Resumes the cobot after an interruption that paused it, when no other keeps it paused.

    A resume that fails is left for the sweeper, which sends it again until it succeeds.
    """
    won = _claim(interruption_id, Q(ended_at__isnull=False, resumed_at__isnull=True))
    if won is None:
        return
    claimed, cobot = won
    others = Interruption.objects.filter(
        cobot=cobot, mode=claimed.mode, ended_at__isnull=True, paused_at__isnull=False
    ).exclude(pk=claimed.pk)
    needed = claimed.paused_at is not None and not others.exists()
    needed = needed and cobot.stopped_at is None  # a STOP's resume restarts it
    error = _command(claimed, cobot, pause=False) if needed else ""
    with transaction.atomic():
        if error:
            _record(claimed, error=f"resume: {error}")
            return
        _record(claimed, resumed_at=timezone.now())
        ring_next_job_on_commit(cobot.pk)  # the queue waited for this to settle


def set_speed_before_step(cobot_id: int) -> bool:
    """Gives the cobot the speed its next step runs at, before the step goes: full speed
    restored after the slowdowns that ended, then slowed for those still open (a step that
    starts beside an operator); whether none is left unsent (another sender may hold one)."""
    # One statement for the common case, a step with no slowdown to set: it is on every step.
    due = list(progress.speed_changes_due(cobot_id).values_list("pk", "ended_at"))
    if not due:
        return True
    # The restores first, then the slowdowns still open: a step beside an operator goes slowly.
    for interruption_id, ended_at in sorted(due, key=lambda row: row[1] is None):
        if ended_at is not None:
            resume_cobot(interruption_id)
        else:
            interrupt_cobot(interruption_id)
    return not progress.speed_changes_due(cobot_id).exists()


def _claim(interruption_id: int, due: Q) -> tuple[Interruption, Cobot] | None:
    """The interruption and its cobot, once this sender alone may command the cobot for it;
    None when it is not `due` (nor a pause or a slowdown), or another sender holds it."""
    now = timezone.now()
    free = Q(claimed_at__isnull=True) | Q(claimed_at__lt=now - CLAIM_EXPIRES)
    with transaction.atomic():
        won = Interruption.objects.filter(
            due, free, pk=interruption_id, mode__in=COMMANDED_MODES
        ).update(claimed_at=now)
    if not won:
        return None
    claimed = Interruption.objects.select_related("cobot").get(pk=interruption_id)
    assert claimed.cobot is not None  # a pause or a slowdown holds a cobot's step
    return claimed, claimed.cobot


def _record(interruption: Interruption, **outcome: object) -> None:
    """Writes the outcome and gives the claim back; call inside the recording transaction."""
    Interruption.objects.filter(pk=interruption.pk).update(claimed_at=None, **outcome)


def _command(interruption: Interruption, cobot: Cobot, *, pause: bool) -> str:
    """Pauses or resumes (slows or restores the speed of) the cobot; "" when done, else why not."""

    def send() -> None:
        driver = driver_for_cobot(cobot)
        if interruption.mode == "slow":
            speed = SLOW_OVERRIDE_PERCENT if pause else FULL_OVERRIDE_PERCENT
            driver.write({urua.STATE_OVERRIDE: speed})
        else:
            driver.call("PauseProgram" if pause else "StartProgram")

    try:
        outside_transaction(send)
    except DriverError as error:
        return str(error)
    return ""


def ring_next_job_on_commit(cobot_id: int) -> None:
    """Starts the cobot's first queued job once the transaction commits, if one waits."""
    job_id = (
        Job.objects.filter(cobot_id=cobot_id, state=JobState.QUEUED)
        .values_list("pk", flat=True)
        .first()
    )
    if job_id is not None:
        dispatch.send_on_commit(Task.RUN_JOB, job_id)


def holds_cobot(cobot_id: int) -> bool:
    """Whether an operator's interruption still keeps the cobot paused (a STOP's resume asks)."""
    return progress.unsettled_pauses(cobot_id).exists()


def to_redo() -> list[tuple[Task, int]]:
    """Pauses that failed while the interruption is open, resumes not yet done after it ended."""
    commanded = Interruption.objects.filter(mode__in=COMMANDED_MODES)
    pauses = commanded.filter(ended_at__isnull=True, paused_at__isnull=True).exclude(error="")
    resumes = commanded.filter(ended_at__isnull=False, resumed_at__isnull=True)
    return [(Task.INTERRUPT_COBOT, pk) for pk in pauses.values_list("pk", flat=True)] + [
        (Task.RESUME_COBOT, pk) for pk in resumes.values_list("pk", flat=True)
    ]
