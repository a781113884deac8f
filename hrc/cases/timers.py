"""Timers of running cases rung when due: the worker's side (progress.arm_timers arms them).

A timer transition fires once it has been enabled for its duration without
interruption. Every change of a case's marking arms the timers it newly enables
(a CaseTimer row, due at its duration times the case's timer scale) and disarms
those it no longer enables, in the transaction that changes the marking; after
commit a delayed task rings the timer's doorbell at its due time. The row is the
truth: a lost doorbell costs only latency (the sweeper rings overdue timers, and
those due too far ahead for a doorbell), and a second one finds the timer fired and
does nothing, so a timer fires at most once.
"""

from __future__ import annotations

import datetime as dt

from django.db import transaction
from django.utils import timezone

from hrc.cases import dispatch, progress
from hrc.cases.choices import CaseStatus, TimerState
from hrc.cases.dispatch import Task
from hrc.cases.models import CaseTimer
from hrc.cases.nets import net_of
from hrc.engine.runtime import NotEnabled

# The sweeper leaves a timer this long past due to its own doorbell.
SWEEP_GRACE_SECONDS = 1.0


def ring_timer(timer_id: int) -> bool:
    """Fires the timer's transition when the timer is still armed and due and its case running
    (a suspended case's wait until it resumes); returns whether it fired. A doorbell that comes
    early rings again when the timer is due. Safe to call any number of times."""
    armed = CaseTimer.objects.filter(pk=timer_id, state=TimerState.ARMED)
    case_id = armed.values_list("case_id", flat=True).first()
    if case_id is None:
        return False  # fired, disarmed, or never committed
    with transaction.atomic():
        case = progress.lock_case(case_id)
        timer = CaseTimer.objects.get(pk=timer_id)  # the case row lock guards its timers
        if timer.state != TimerState.ARMED or case.status != CaseStatus.RUNNING:
            return False
        if timer.due_at > timezone.now():
            progress.ring_timer_on_commit(timer)
            return False
        net = net_of(case)
        try:
            progress.fire_timer(case, net, timer)
        except NotEnabled:  # arm_timers keeps armed timers enabled; should that fail, disarm
            progress.arm_timers(case, net)
        case.save()
    return timer.state == TimerState.FIRED


def sweep_timers() -> int:
    """Rings for the armed timers of running cases that are overdue: their doorbell was lost
    (the broker or the server restarted), or they were due too far ahead to get one
    (progress.DOORBELL_HORIZON_SECONDS). Returns how many."""
    overdue = list(
        CaseTimer.objects.filter(
            state=TimerState.ARMED, case__status=CaseStatus.RUNNING,
            due_at__lt=timezone.now() - dt.timedelta(seconds=SWEEP_GRACE_SECONDS),
        ).values_list("pk", flat=True)[:100]
    )  # fmt: skip
    with transaction.atomic():  # send_on_commit needs a transaction to wait for
        for timer_id in overdue:
            dispatch.send_on_commit(Task.RING_TIMER, timer_id)
    return len(overdue)
