"""Running device calls: each device of a cell has a queue of its own (the worker's side).

A device call (a linear axis move, a part scan, a display text) is its
device's job, not its cobot's: one call at a time per device, first come
first served, and a cobot step of the same cell runs meanwhile when nothing
in the pattern orders them. `run_next_device_job` takes the device's row
lock, and only when no call of that device is running does it lease the
first queued call that may start. Lock order: device row, then case row,
then job row (as a cobot's queue: cobot row, case, job; jobs.py).

The call goes out through the gateway of the cobot that serves the device
(Device.gateway). Finishing, failing (retries, incidents), lease expiry and
the sweeper are the cobot jobs' (jobs.finish_job, jobs.fail_job, jobs.sweep):
the rows are the same. A call that may have gone out unanswered is never sent
again by itself (Job.sent_at); it becomes an incident naming the device.
A STOP of the device's cell holds its queue: no call starts meanwhile.
"""

from __future__ import annotations

import datetime as dt
import logging
from collections.abc import Iterable
from typing import Any

from django.conf import settings
from django.db import transaction
from django.db.models import Exists, Q, QuerySet
from django.utils import timezone

from hrc.cases import dispatch, jobs, progress, rows
from hrc.cases.choices import CaseStatus, JobState, WorkItemState
from hrc.cases.dispatch import Task
from hrc.cases.models import Job
from hrc.cases.nets import net_of
from hrc.cobots.drivers.base import CommandRefused, DriverError
from hrc.cobots.drivers.runner import driver_for_cobot
from hrc.cobots.models import CellStop, Device
from hrc.engine.petri import Marking

logger = logging.getLogger(__name__)

# The name of the gateway session the devices' calls go through (runner.driver_for).
DEVICE_SESSION = "devices"


def is_device_job(job_id: int) -> bool:
    """Whether the job is a device's (its doorbell rings the device's queue)."""
    return bool(_on_a_device(job=job_id))


@rows.Compiled
def _on_a_device(job: int) -> QuerySet[Job, Any]:  # asked on every doorbell: compiled once
    return Job.objects.filter(pk=job, device__isnull=False).values_list("pk")


def run_next_device_job(job_id: int) -> None:
    """Runs the next call of `job_id`'s device, if one may run now; safe to call any number of
    times."""
    lease = lease_next_device_job(Q(jobs__pk=job_id))
    if lease is None:
        return
    sent: list[dt.datetime] = []
    try:
        result = _call(lease, sent)
    except DriverError as error:
        jobs.fail_job(lease, _naming_device(lease, error), accepted_at=_first(sent))
    except Exception as error:
        # A fault of ours: whether the call went out is unknown, so it is never sent again.
        logger.exception("Device job %s failed unexpectedly", lease.job_id)
        message = (
            f"hrc failed while calling device {_device_name(lease)} ({error!r}); the call is not "
            "sent again by itself. See the workers' log, check the device, then retry or skip."
        )
        jobs.fail_job(lease, DriverError(message), accepted_at=_first(sent))
    else:
        jobs.finish_job(lease, result, accepted_at=_first(sent))


def lease_next_device_job(which: Q) -> jobs.Lease | None:
    """Leases the first queued call of the device `which` selects that may start now; None when
    none may (one runs, the device is out of service, its cell is stopped)."""
    now = timezone.now()
    with transaction.atomic():
        # NO KEY, as the cobot's: a case service inserting a job holds a key-share lock on
        # the device row (the foreign key) while it holds its case.
        device = (
            Device.objects.select_for_update(of=("self",), no_key=True)
            .select_related("gateway")
            .filter(which)
            .first()
        )
        if device is None:
            return None
        held = _why_held(device)
        if held:
            # Said on each queued call, so that the supervisor sees why nothing moves.
            waiting = Job.objects.filter(device=device, state=JobState.QUEUED)
            waiting.exclude(waiting_for=held).update(waiting_for=held)
            return None
        queued = (
            Job.objects.filter(
                device=device, state=JobState.QUEUED, next_try_at__lte=now,
                case__status=CaseStatus.RUNNING,
            )
            .annotate(busy=Exists(Job.objects.filter(device=device, state=JobState.RUNNING)))
            .values_list("pk", "case_id", "busy")[: settings.HRC_QUEUE_LOOKAHEAD]
        )  # fmt: skip
        for job_id, case_id, busy in list(queued):
            if busy:
                return None
            lease = _lease_if_ready(device, job_id, case_id, now)
            if lease is not None:
                return lease
    return None


def _why_held(device: Device) -> str:
    """Why none of the device's calls may start now; "" when they may."""
    if not device.is_active:
        return f"device {device.name} to be put back in service"
    if cell_stopped(device):
        return f"cell {device.cell} to be resumed after its STOP"
    return ""


def cell_stopped(device: Device) -> bool:
    """Whether a tablet's STOP holds the device's cell (hrc.cobots.stops)."""
    return bool(device.cell) and (
        CellStop.objects.filter(
            organisation_id=device.organisation_id, cell=device.cell, resumed_at__isnull=True
        ).exists()
    )


def _lease_if_ready(
    device: Device, job_id: int, case_id: int, now: dt.datetime
) -> jobs.Lease | None:
    """Leases the call when its task may start now, else records why it waits."""
    case, job = jobs.lock_case_and_job(case_id, job_id)
    if job.state != JobState.QUEUED or case.status != CaseStatus.RUNNING:
        return None
    item = job.work_item
    net = net_of(case)
    if item.state == WorkItemState.OFFERED:
        waiting = net.why_not(Marking(case.marking), f"start:{item.task}")
        if waiting:
            jobs.record_waiting(job, waiting)
            return None
    progress.lease_job(case, net, job, now, held_by=progress.worker_name())
    case.save()
    return jobs.Lease(
        job.pk, case.pk, job.lease, job.attempt, job.kind, job.command, job.timeout,
        device.gateway, sent_before=job.sent_at is not None, device=device,
    )  # fmt: skip


def _call(lease: jobs.Lease, sent: list[dt.datetime]) -> dict[str, Any]:
    """Sends the call once: marked sent first, so a lost answer is never followed by a resend."""
    command = lease.command
    name = _device_name(lease)
    if lease.sent_before:
        raise CommandRefused(
            f"{command['method']} went to device {name} before and its answer was lost; it is "
            "not sent again by itself. Check the device, then retry or skip."
        )
    # A session of its own on the gateway: a gateway answers one session's requests one after
    # another, and a call that lasts (an axis move) would hold up its cobot's step handshake.
    driver = driver_for_cobot(lease.cobot, step_timeout=lease.timeout, session=DEVICE_SESSION)
    marked = Job.objects.filter(pk=lease.job_id, lease=lease.lease, state=JobState.RUNNING)
    if not marked.update(sent_at=timezone.now()):
        raise CommandRefused("The call was taken over by another worker before it was sent.")
    sent.append(timezone.now())
    values = driver.call(command["method"], *command["args"], timeout=lease.timeout)
    return dict(zip(command["outputs"], values, strict=False))


def _naming_device(lease: jobs.Lease, error: DriverError) -> DriverError:
    """The error with the device named, as the incident on its work item shows it."""
    named = type(error)(
        f"Device {_device_name(lease)} (through {lease.cobot.name}'s gateway): {error}",
        state=error.state,
    )
    return named


def _device_name(lease: jobs.Lease) -> str:
    return lease.device.name if lease.device is not None else lease.cobot.name


def _first(sent: list[dt.datetime]) -> dt.datetime | None:
    return sent[0] if sent else None


# Doorbells ---------------------------------------------------------------------------


def ring_devices_on_commit(device_ids: Iterable[int]) -> None:
    """Rings each device's queue once the transaction commits, when a call is queued (a STOP
    of their cell was resumed)."""
    first_queued = (
        Job.objects.filter(device_id__in=list(device_ids), state=JobState.QUEUED)
        .order_by("device_id", "queued_at", "id")
        .distinct("device_id")
        .values_list("pk", flat=True)
    )
    for job_id in first_queued:
        dispatch.send_on_commit(Task.RUN_JOB, job_id)


def device_queue(device: Device | int) -> list[Job]:
    """The device's queued and running calls, first come first."""
    return list(
        Job.objects.filter(device=device, state__in=[JobState.QUEUED, JobState.RUNNING])
        .select_related("case", "work_item")
        .order_by("queued_at", "id")
    )
