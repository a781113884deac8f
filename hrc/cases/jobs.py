"""Running jobs on cobots: the worker's side of a case. Called by the thin Celery tasks.

(A device's calls have a queue of their own, hrc.cases.device_jobs; they share this
module's finish and fail paths, and its sweeper. Lock order: cobot row, or a device job's
device row, then case row, then job row; a worker that leases the cobot's next job while it
holds the case it finished takes both rows without waiting, SKIP LOCKED.)

One cobot runs one job at a time. `run_next_job` takes the cobot's row lock,
and only when no job of that cobot is running does it lease the first
queued job that may start (first come, first served; a job whose case is
suspended, whose task waits for a constraint, or whose cobot is paused for
an operator in a shared area waits and says why). A cobot whose task another
case's func constraint holds (its step done, the supported task not yet) is
that case's until the hold ends: other cases' jobs wait ("holding for: …").
The lease is the lock: a worker that lost it (killed, too slow) may change
nothing afterwards.

Exactly once: a step carries the fencing token (job id, attempt) and the
driver checks the cobot's registers before sending, so automatic retries and
re-leased jobs keep the token and never move the robot twice. A device call
has no token: one that may have gone out unanswered is never repeated by
itself; it becomes an incident.
"""

from __future__ import annotations

import datetime as dt
import logging
import math
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any, cast

from django.conf import settings
from django.db import transaction
from django.db.models import Exists, OuterRef, QuerySet, Subquery
from django.utils import timezone

from hrc.cases import dispatch, events, interruptions, progress, rows
from hrc.cases.choices import (
    OPEN_CASE_STATUSES,
    CaseStatus,
    EventType,
    IncidentKind,
    JobState,
    WorkItemKind,
    WorkItemState,
)
from hrc.cases.dispatch import Task
from hrc.cases.models import Case, Job, WorkItem
from hrc.cases.nets import net_of
from hrc.cases.selectors import holding_work_items, why_held
from hrc.cobots.control import running_commands
from hrc.cobots.drivers import readiness
from hrc.cobots.drivers.base import (
    CobotPaused,
    CommandRefused,
    DriverError,
    Fence,
    StepCommand,
)
from hrc.cobots.drivers.runner import SyncDriver, driver_for_cobot
from hrc.cobots.models import Cobot, Device
from hrc.engine.petri import Marking
from hrc.engine.runtime import CaseNet
from hrc_gateway import urua

logger = logging.getLogger(__name__)

# Lease expiries of one job after which a person decides (a job that kills its worker).
MAX_LEASE_EXPIRIES = 3


@dataclass(frozen=True)
class Lease:
    """What a worker needs to drive one job, read while it held the locks."""

    job_id: int
    case_id: int
    lease: int
    attempt: int
    kind: str
    command: dict[str, Any]
    timeout: float
    cobot: Cobot  # a device job's: the cobot whose gateway serves the device
    sent_before: bool
    device: Device | None = None
    # Whether a slowdown, or its end, may wait to be sent before the step: a lease taken by a
    # worker asks (interruptions.set_speed_before_step); a leased job's message says.
    speed_due: bool = True

    @classmethod
    def from_message(cls, message: Mapping[str, Any]) -> Lease:
        """The lease a completion took for a worker (progress.leased_message)."""
        cobot = message["cobot"]
        return cls(
            message["job"], message["case"], message["lease"], message["attempt"],
            message["kind"], message["command"], message["timeout"],
            Cobot(**{field: cobot[field] for field in progress.COBOT_FIELDS}),
            sent_before=False, speed_due=cobot["speed_due"],
        )  # fmt: skip


def run_leased_job(message: Mapping[str, Any]) -> None:
    """Drives a job a completion leased for the workers (progress.hand_over), once this worker
    has claimed it: straight to the cobot, the lease in hand. A duplicate of the message (the
    sweeper sends it again while nobody has claimed it) finds it claimed and does nothing."""
    lease = Lease.from_message(message)
    _drive(lambda: lease if _claim(lease) else None)


def _claim(lease: Lease) -> bool:
    """Makes the leased job this worker's, if it is still leased as the message says and no
    worker has claimed it: one statement, outside any transaction (the lease is the lock)."""
    claimed = rows.update_where(
        Job, {"held_by": progress.worker_name()},
        "id = %s AND lease = %s AND state = %s AND held_by = ''",
        [lease.job_id, lease.lease, JobState.RUNNING],
    )  # fmt: skip
    return bool(claimed)


def run_next_job(job_id: int) -> None:
    """Runs the next job of `job_id`'s cobot, if one may run now; safe to call any number of times."""
    _drive(
        lambda: _lease_next(f"id = (SELECT cobot_id FROM {rows.table(Job)} WHERE id = %s)", job_id)
    )


def _drive(take: Callable[[], Lease | None]) -> None:
    """Drives the job `take` leases, if any, and records how it ended; then leases the cobot's
    next job itself, as the cobot is free now (no doorbell: progress.hand_over leaves a step
    queued behind a running one to this). That job is driven here too while this task is
    younger than HRC_CHAIN_SECONDS, else handed to the workers, so that a worker serving a
    busy cobot lets the other cobots' doorbells have their turn."""
    began = time.monotonic()

    def old() -> bool:
        return time.monotonic() - began >= settings.HRC_CHAIN_SECONDS

    lease = take()
    while lease is not None:
        lease = _run(lease, hand_over=old)


def _run(lease: Lease, hand_over: Callable[[], bool]) -> Lease | None:
    """Drives one leased job, records how it ended and leases the cobot's next job: the lease
    returned, for this worker to drive; None when there is none, or when `hand_over()`, asked
    once the step has ended, said it goes to the workers (its message sent on commit)."""
    # The cobot first, the tablets right after: what taking the job broadcasts (its task
    # started, the queue) waits until the cobot has accepted the step (events.hold_publishing).
    hold = events.hold_publishing()
    # When the cobot accepted the step: its work starts there, not at the lease (analytics).
    accepted: list[dt.datetime] = []

    def on_sent() -> None:  # on the drivers' event loop: no database here
        accepted.append(timezone.now())
        hold.release()

    result: dict[str, Any] = {}
    failure: DriverError | None = None
    try:
        result = _execute(lease, on_sent=on_sent)
    except DriverError as error:
        failure = error
    except Exception as error:
        # A fault of ours, not the cobot's answer: the step's outcome is unknown, so it is
        # never sent again by itself (a person retries, with the step's token).
        logger.exception("Job %s failed unexpectedly", lease.job_id)
        failure = DriverError(
            f"hrc failed while running the step ({error!r}); it is not sent again by itself. "
            "See the workers' log, check the cobot, then retry or skip."
        )
    finally:
        hold.release()
    accepted_at, handing = (accepted[0] if accepted else None), hand_over()
    if failure is not None:
        fail_job(lease, failure, accepted_at=accepted_at)
        taken = _lease_next("id = %s", lease.cobot.pk, hand_over=handing)
    else:
        taken = _finish_and_lease_next(lease, result, accepted_at=accepted_at, hand_over=handing)
    return None if handing else taken


def lease_next_job(cobot_id: int) -> Lease | None:
    """The lease of the cobot's next job, taken for this process: a job a completion leased
    for the workers that none has claimed (claimed now), else the first queued job that may
    start now (leased now); None when there is none.

    Starting the job's task (its `start` firing) happens with the lease, in the same
    transaction: the cobot taking the job is the moment the task starts.
    """
    for message in _unclaimed(timezone.now(), cobot_id=cobot_id):
        lease = Lease.from_message(message)
        if _claim(lease):
            return lease
    return _lease_next("id = %s", cobot_id)


def _lease_next(which: str, key: int, *, hand_over: bool = False) -> Lease | None:
    """`lease_next_job` for the cobot `which` selects (SQL over the cobot's columns, `key` its
    parameter: the cobot's own id, or one of its jobs'). `hand_over`: the lease is taken for
    the workers, its message sent once it commits (run_leased_job): not this caller's to drive."""
    with transaction.atomic():
        return _take_next(which, key, hand_over=hand_over, wait=True)


class _LockTaken(Exception):
    """A row that a lease taken without waiting needs is locked by another session."""


def _take_next(which: str, key: int, *, hand_over: bool, wait: bool) -> Lease | None:
    """_lease_next in the caller's transaction. `wait=False`: raises _LockTaken rather than wait
    for the cobot's row or a queued job's case (SKIP LOCKED); what it wrote before stands."""
    now = timezone.now()
    # The lock first, then the reasons to wait in a statement of their own: a statement
    # sees what was committed when it began, so one that waited for the lock would not
    # see the job the lease before it took (READ COMMITTED; tests/cases/test_cobot_lock.py).
    # NO KEY: a case service inserting a job or an interruption takes a key-share lock
    # on the cobot row (the foreign key) while it holds its case; FOR UPDATE would
    # wait for it while we wait for the case, a deadlock.
    # A locked row is read as it is now, whatever the statement's snapshot: its own
    # columns (stopped_at) may come with the lock.
    cobot = rows.fetch_one(Cobot, which, [key], lock=_row_lock(wait))
    if cobot is None:
        if not wait:
            raise _LockTaken(f"cobot {which} ({key})")
        return None
    if cobot.stopped_at is not None:  # a tablet's STOP holds the cobot (hrc.cobots.stops)
        return None
    # The queue, with the reasons the whole cobot waits (a job running, a pause for an
    # operator in a shared area) on each row: a second statement, so they are fresh.
    # `held`: another case's func hold reserves the cobot; the holding case's own jobs
    # may go (its pattern may give the cobot the supported task itself).
    queued = _queue(cobot=cobot.pk, now=now)
    for job_id, case_id, busy, paused, held, commanded, speed_due in queued:
        if busy or paused or commanded:
            return None
        lease = _lease_if_ready(
            cobot, job_id, case_id, now,
            held=held, speed_due=speed_due, hand_over=hand_over, wait=wait,
        )  # fmt: skip
        if lease is not None:
            return lease
    return None


def _row_lock(wait: bool) -> str:
    return "FOR NO KEY UPDATE" if wait else "FOR NO KEY UPDATE SKIP LOCKED"


@rows.Compiled
def _queue(cobot: int, now: dt.datetime) -> QuerySet[Job, Any]:
    """The cobot's queue, with the reasons the whole cobot waits on each row (a job running, a
    pause for an operator in a shared area, a person's command (power, program) under way).
    `held`: another case's func hold reserves the cobot; the holding case's own jobs may go
    (its pattern may give the cobot the supported task itself). `speed_due`: a slowdown or its
    end waits to be sent (the worker sends it before the step)."""
    return Job.objects.filter(
        cobot=cobot, state=JobState.QUEUED, next_try_at__lte=now, case__status=CaseStatus.RUNNING,
    ).annotate(
        busy=Exists(Job.objects.filter(cobot=cobot, state=JobState.RUNNING)),
        paused=Exists(progress.unsettled_pauses(cobot)),
        held=Exists(_held_by_another_case(cobot)),
        commanded=Exists(running_commands(now).filter(cobot=cobot)),
        speed_due=Exists(progress.speed_changes_due(cobot)),
    ).values_list("pk", "case_id", "busy", "paused", "held", "commanded", "speed_due")[
        : settings.HRC_QUEUE_LOOKAHEAD
    ]  # fmt: skip


def _held_by_another_case(cobot_id: int | OuterRef) -> QuerySet[WorkItem]:
    """The cobot's holding work items of cases other than the outer job's (OuterRef case_id)."""
    return holding_work_items().filter(cobot_id=cobot_id).exclude(case_id=OuterRef("case_id"))


def _lease_if_ready(
    cobot: Cobot,
    job_id: int,
    case_id: int,
    now: dt.datetime,
    *,
    held: bool,
    speed_due: bool,
    hand_over: bool,
    wait: bool,
) -> Lease | None:
    """Leases the job when it may start now, else records why it waits; `held` and `speed_due`
    are the queue statement's (_queue; a hold is asked again here); `hand_over` as in
    _lease_next, `wait` as in _take_next."""
    case, job = lock_case_and_job(case_id, job_id, wait=wait)
    if job.state != JobState.QUEUED or case.status != CaseStatus.RUNNING:
        return None
    item = job.work_item
    net = net_of(case)
    # Asked again under the locks: the hold may have ended since the queue was read (it ends
    # in a transaction of its own, then rings the doorbell).
    waiting = why_held(cobot.pk, other_than=case.pk) if held else ""
    if not waiting and (waiting := _why_waiting(case, net, item)):
        case.save(update_fields=["last_seq"])  # the wait is recorded (progress.keep_out)
    if not waiting and item.state == WorkItemState.OFFERED:
        waiting = net.why_not(Marking(case.marking), f"start:{item.task}")
    if waiting:
        if record_waiting(job, waiting):
            events.publish_cobot_queue(cobot.pk)
        return None
    progress.lease_job(case, net, job, now, held_by="" if hand_over else progress.worker_name())
    case.save()
    events.publish_cobot_queue(cobot.pk)
    speed_due = speed_due or item.task in net.space_tasks  # a start beside an operator slows it
    if hand_over:
        message = progress.leased_message(job, progress.cobot_fields(cobot), speed_due)
        dispatch.send_on_commit(Task.RUN_LEASED_JOB, message)
    return Lease(
        job.pk, case.pk, job.lease, job.attempt, job.kind, job.command, job.timeout, cobot,
        sent_before=job.sent_at is not None, speed_due=speed_due,
    )  # fmt: skip


def lock_case_and_job(case_id: int, job_id: int, *, wait: bool = True) -> tuple[Case, Job]:
    """Both rows locked, in the project's lock order (case, then job), and the job's work item
    with them, in one statement. The work item is locked too, so that all three are read as
    they are once the locks are held: a locked row is read in its newest committed version,
    another row as the statement found it before any wait (READ COMMITTED). `wait=False`:
    _LockTaken when another session holds one of them."""
    case, job, item = (rows.table(model) for model in (Case, Job, WorkItem))
    where = (
        f"{case}.id = %s AND {job}.id = %s AND {job}.case_id = {case}.id "
        f"AND {item}.id = {job}.work_item_id"
    )
    found = rows.fetch_each((Case, Job, WorkItem), where, [case_id, job_id], lock=_row_lock(wait))
    if found is None and not wait:
        raise _LockTaken(f"case {case_id} or its job {job_id}")
    if found is None:
        raise Job.DoesNotExist(f"There is no job {job_id} in case {case_id}.")
    locked_case, locked_job, locked_item = cast(tuple[Case, Job, WorkItem], found)
    locked_job.work_item = locked_item
    return locked_case, locked_job


def record_waiting(job: Job, waiting: str) -> bool:
    """Says on the queued job why it waits; whether that changed (the queue's view then too)."""
    if job.waiting_for == waiting:
        return False
    job.waiting_for = waiting
    job.save(update_fields=["waiting_for"])
    return True


def _why_waiting(case: Case, net: CaseNet, item: WorkItem) -> str:
    """Why a cobot task must not start now although the marking allows it; "" when it may.

    A step kept out of a shared area waits, recorded as an interruption of its task until
    the task in the area completes (which rings this job's doorbell: progress)."""
    kept_out = progress.kept_out_by(case, net, item)
    if kept_out is None:
        return ""
    if item.state != WorkItemState.OFFERED:  # started, then paused: the pause is its record
        return f"{kept_out[1].label} is in the shared area (space constraint)"
    return progress.keep_out(case, item, *kept_out)


def _execute(lease: Lease, on_sent: Callable[[], None]) -> dict[str, Any]:
    """Drives the job; `on_sent` is called once its step is accepted, or before a device call."""
    driver = driver_for_cobot(lease.cobot, step_timeout=lease.timeout)
    command = lease.command
    if lease.kind == WorkItemKind.DEVICE:
        on_sent()  # a call (an inspection, say) may take a while: tablets need not wait for it
        return _call_device(driver, lease)
    _prepare(driver, lease.cobot.pk, command["program"], lease.timeout)
    if lease.speed_due and not interruptions.set_speed_before_step(lease.cobot.pk):
        raise CobotPaused(
            f"{driver.name}'s speed for an operator in its shared area is not set yet; "
            "the step waits until it is."
        )
    step = StepCommand(
        step=command["number"], fence=Fence(lease.job_id, lease.attempt),
        workspace=command["workspace"], poses=command["poses"],
    )  # fmt: skip
    result = driver.run_step(step, timeout=lease.timeout, on_sent=on_sent)
    if result.outcome not in ("ran", "duplicate"):
        raise CommandRefused(
            f"{lease.cobot.name}'s program answered step {step.step} of {command['program']} "
            f"with {result.outcome!r}."
        )
    return {"outcome": result.outcome, "seconds": round(result.seconds, 3)}


def _prepare(driver: SyncDriver, cobot_id: int, program: str, timeout: float) -> None:
    """Loads and plays the step's program when the cobot is idle in another one.

    Never powers the arm on, releases its brakes or clears a stop: a cobot that
    is not running (powered, brakes released) raises the error that names its
    state and what a person does (readiness.not_ready); one on its way up is
    retried. Nor does it play a program paused since the lease (a tablet's STOP,
    an operator in a shared area): CobotPaused puts the step back in the queue.
    """

    def ready(state: dict[str, Any]) -> bool:
        return _loaded(state) == program and state.get("ProgramState") == urua.PROGRAM_PLAYING

    # The subscription's view saves a round trip per step; the step's own
    # handshake reads afresh if the cobot is not ready after all.
    if ready(driver.state(fresh=False)):
        return
    state = driver.state()
    if ready(state):
        return
    loaded = str(state.get("CurrentProgram") or "")
    problem = readiness.not_ready(driver.name, state, page=readiness.page_of(cobot_id))
    if problem is not None:
        # The incident keeps the cobot's state by node path, as the driver's own errors do
        # (state() names the variables by their short names): one shape whatever noticed it.
        by_path = {f"State/{name}": value for name, value in state.items()}
        raise type(problem)(str(problem), state=by_path)
    # A STOP from a tablet, or an operator entering a shared area, may have paused the
    # program since the lease: playing it again here would undo the pause.
    if Cobot.objects.filter(pk=cobot_id, stopped_at__isnull=False).exists():
        raise CobotPaused(
            f"{driver.name}'s cell was stopped from a tablet; the step waits until it is resumed.",
            state=state,
        )
    if progress.unsettled_pauses(cobot_id).exists():
        raise CobotPaused(
            f"{driver.name} is paused for an operator in a shared area; the step waits until "
            "the operator's task ends.",
            state=state,
        )
    if _loaded(state) != program:
        # Another pattern's program, idle between steps (no job of this cobot runs but
        # ours): a program is loaded only once it has stopped.
        if loaded and state.get("ProgramState") != urua.PROGRAM_STOPPED:
            driver.call("StopProgram", timeout=timeout)
        driver.call("SelectProgram", program, timeout=timeout)
    driver.call("StartProgram", timeout=timeout)


def _loaded(state: dict[str, Any]) -> str:
    """The base name of the program the cobot has loaded; "" when none is."""
    loaded = str(state.get("CurrentProgram") or "").strip()
    return urua.program_base_name(loaded) if loaded else ""


def _call_device(driver: SyncDriver, lease: Lease) -> dict[str, Any]:
    command = lease.command
    if lease.sent_before:
        raise CommandRefused(
            f"{command['method']} went to {lease.cobot.name} before and its answer was lost; "
            "it is not sent again by itself. Check the device, then retry or skip."
        )
    if not _mark_sent(lease):
        raise CommandRefused("The job was taken over by another worker before it was sent.")
    values = driver.call(command["method"], *command["args"], timeout=lease.timeout)
    return dict(zip(command["outputs"], values, strict=False))


def _mark_sent(lease: Lease) -> bool:
    return bool(
        Job.objects.filter(pk=lease.job_id, lease=lease.lease, state=JobState.RUNNING).update(
            sent_at=timezone.now()
        )
    )


def finish_job(
    lease: Lease, result: dict[str, Any], *, accepted_at: dt.datetime | None = None
) -> None:
    """Records a job's success and completes its task (now, or once func constraints allow);
    the doorbell of the job's queue rings after the commit. `accepted_at`: when the cobot
    accepted the step (the driver's on_sent); the lease's start when not given."""
    with transaction.atomic():
        job = _finish(lease, result, accepted_at)
        if job is not None:
            _ring_for_next_on_commit(job)


def _finish_and_lease_next(
    lease: Lease, result: dict[str, Any], *, accepted_at: dt.datetime | None, hand_over: bool
) -> Lease | None:
    """finish_job without the doorbell, and the cobot's next job leased (as _lease_next) in the
    same transaction: one commit where there were two. It holds the finished case's lock, so
    it waits for no other: where the cobot's row or the next job's case is locked, the next job
    is leased after the commit, as a doorbell leases it."""
    with transaction.atomic():
        _finish(lease, result, accepted_at)
        try:
            return _take_next("id = %s", lease.cobot.pk, hand_over=hand_over, wait=False)
        except _LockTaken:
            pass
    return _lease_next("id = %s", lease.cobot.pk, hand_over=hand_over)


def _finish(lease: Lease, result: dict[str, Any], accepted_at: dt.datetime | None) -> Job | None:
    """finish_job's writes, in the caller's transaction: the job; None when this worker's lease
    is no longer the job's (nothing written)."""
    case, job = _locked_job(lease)
    if job is None:
        return None
    job.state, job.result, job.ended_at = JobState.SUCCEEDED, result, timezone.now()
    job.accepted_at = accepted_at or job.started_at
    # Written with the case: what the task's completion reads of jobs is other jobs'.
    case.keep(job, ["state", "result", "ended_at", "accepted_at"])
    if job.work_item.state == WorkItemState.CANCELLED:
        events.record_event(
            case, EventType.CANCELLED_STEP_ENDED, item=job.work_item, detail={"result": result}
        )
    elif case.status in OPEN_CASE_STATUSES:
        progress.complete_cobot_task(case, net_of(case), job.work_item, result)
    case.save()
    return job


def _ring_for_next_on_commit(job: Job) -> None:
    """Rings the doorbell of the job's queue (its cobot's or its device's) for the next job once
    this transaction has committed, if one is queued then (progress.ring_for_next_on_commit)."""
    progress.ring_for_next_on_commit(job)


def _publish_queue(job: Job) -> None:
    if job.cobot_id is not None:  # a device's queue is read afresh (device_jobs.device_queue)
        events.publish_cobot_queue(job.cobot_id)


def fail_job(lease: Lease, error: DriverError, *, accepted_at: dt.datetime | None = None) -> None:
    """Retries a transient failure with back-off (same token); anything else, and a transient
    one with no retry left, becomes an incident at once. Either way the error is the job's
    `last_error` and an event of the case's timeline. `accepted_at`: when the cobot accepted
    the step, None when it never did (then the cobot did no work for it)."""
    with transaction.atomic():
        case, job = _locked_job(lease)
        if job is None:
            return
        job.last_error, job.accepted_at = str(error), accepted_at
        if _ended_with_case(case, job):
            return
        item = job.work_item
        if isinstance(error, CobotPaused):
            # Not sent, and nothing a retry would change: back in the queue, which waits for
            # the pause to end (an interruption settled, a STOP resumed) before it leases again.
            job.state, job.next_try_at = JobState.QUEUED, timezone.now()
            job.save()
            events.record_event(
                case, EventType.STEP_RETRY, item=item,
                detail={"error": str(error), "in_seconds": 0, "retries_left": job.retries_left},
            )  # fmt: skip
            dispatch.send_on_commit(Task.RUN_JOB, job.pk)
        elif error.transient and job.retries_left > 0:
            job.retries_left -= 1
            delay = _backoff(net_of(case).tasks[item.task].retries - job.retries_left)
            job.state, job.next_try_at = (
                JobState.QUEUED,
                timezone.now() + dt.timedelta(seconds=delay),
            )
            job.save()
            events.record_event(
                case, EventType.STEP_RETRY, item=item,
                detail={"error": str(error), "in_seconds": delay, "retries_left": job.retries_left},
            )  # fmt: skip
            dispatch.send_on_commit(Task.RUN_JOB, job.pk, countdown=delay)
        else:
            job.state, job.ended_at = JobState.FAILED, timezone.now()
            job.save()
            events.record_event(
                case, EventType.STEP_FAILED, item=item,
                detail={"error": str(error), "attempt": job.attempt},
            )  # fmt: skip
            kind = (
                IncidentKind.DEVICE_FAILED
                if job.kind == WorkItemKind.DEVICE
                else IncidentKind.STEP_FAILED
            )
            events.open_incident(case, kind, str(error), item=item, cobot_state=error.state)
            _ring_for_next_on_commit(job)  # the cobot's next job may go
        case.save()


def _ended_with_case(case: Case, job: Job) -> bool:
    """A running job whose case ended meanwhile (cancelled, failed), or whose task a transition
    cancelled, ends too: cancelled, never queued again, where it would stay listed for ever (a
    cancelled task's step: with an event saying how it ended). True when it did.

    Call while holding the case row lock."""
    cancelled = job.work_item.state == WorkItemState.CANCELLED
    if case.status in OPEN_CASE_STATUSES and not cancelled:
        return False
    job.state, job.ended_at = JobState.CANCELLED, timezone.now()
    job.save()
    if cancelled:
        events.record_event(
            case, EventType.CANCELLED_STEP_ENDED, item=job.work_item,
            detail={"error": job.last_error or "its worker lost the job"},
        )  # fmt: skip
        case.save()
    _publish_queue(job)
    _ring_for_next_on_commit(job)
    return True


def _backoff(retries_used: int) -> float:
    """Seconds before the next try: HRC_RETRY_BACKOFF, doubling per retry, at most a minute."""
    return float(min(settings.HRC_RETRY_BACKOFF * 2 ** min(max(retries_used - 1, 0), 10), 60.0))


def _locked_job(lease: Lease) -> tuple[Case, Job | None]:
    """The case (locked) and the job, or None when this worker's lease is no longer the job's."""
    case, job = lock_case_and_job(lease.case_id, lease.job_id)
    if job.state != JobState.RUNNING or job.lease != lease.lease:
        logger.info("Job %s: lease %s was lost; its outcome is dropped", job.pk, lease.lease)
        return case, None
    return case, job


# The sweeper ------------------------------------------------------------------------

# When this process last swept (time.monotonic()), for sweep_is_due.
_last_sweep = {"at": -math.inf}


def sweep_is_due() -> bool:
    """Whether this process sweeps now: not when it swept less than half a period ago (and then
    it counts as sweeping now). Beat sends a sweep every HRC_SWEEP_SECONDS whether the last one
    ran or not: those that piled up in the broker while the workers were busy or away would
    run back to back, each a whole sweep, just as the workers catch up."""
    now = time.monotonic()
    if now - _last_sweep["at"] < settings.HRC_SWEEP_SECONDS / 2:
        return False
    _last_sweep["at"] = now
    return True


def sweep() -> dict[str, int]:
    """Finds what the broker lost: expired leases and due jobs. Run every few seconds (beat).

    An expired lease is counted; the job is queued again with its token, or,
    after MAX_LEASE_EXPIRIES, becomes an incident. Then every cobot with a
    due job and nothing running gets its doorbell rung.
    """
    now = timezone.now()
    expired = list(
        Job.objects.filter(state=JobState.RUNNING, lease_expires_at__lt=now).values_list(
            "pk", "case_id"
        )
    )
    for job_id, case_id in expired:
        _expire_lease(job_id, case_id)
    due = _first_due_per_cobot(now)
    unclaimed = _unclaimed(now)
    with transaction.atomic():  # send_on_commit needs a transaction to wait for
        for job_id in due:
            dispatch.send_on_commit(Task.RUN_JOB, job_id)
        for message in unclaimed:
            dispatch.send_on_commit(Task.RUN_LEASED_JOB, message)
        unsettled = interruptions.to_redo()
        for task, interruption_id in unsettled:
            dispatch.send_on_commit(task, interruption_id)
    return {
        "expired": len(expired), "rung": len(due), "unclaimed": len(unclaimed),
        "interruptions": len(unsettled),
    }  # fmt: skip


def _unclaimed(now: dt.datetime, cobot_id: int | None = None) -> list[dict[str, Any]]:
    """The messages of the jobs a completion leased that no worker has claimed: for the sweeper
    (no `cobot_id`), those whose age calls for a copy (_send_again: their message lost with
    the broker, or the workers busy), which it sends again, as a claim takes a lease once;
    else the cobot's. (Left
    unclaimed until the lease expires, a job is queued again: _expire_lease.)"""
    jobs = Job.objects.filter(state=JobState.RUNNING, held_by="", kind=WorkItemKind.STEP)
    period = settings.HRC_SWEEP_SECONDS
    if cobot_id is None:
        jobs = jobs.filter(started_at__lt=now - dt.timedelta(seconds=period))
    else:
        jobs = jobs.filter(cobot_id=cobot_id)
    jobs = jobs.select_related("cobot").order_by("started_at", "id")
    # speed_due: the worker asks, as the slowdowns may have changed since the lease.
    messages = []
    for job in jobs:
        assert job.cobot is not None  # a step's job is on a cobot
        assert job.started_at is not None  # leased
        if cobot_id is None and not _send_again(now - job.started_at, period):
            continue
        messages.append(progress.leased_message(job, progress.cobot_fields(job.cobot), True))
    return messages


def _send_again(age: dt.timedelta, period: float) -> bool:
    """Whether the sweeper sends an unclaimed lease's message again, the lease `age` old: at
    1, 2, 4, 8… sweep periods of age, not at every sweep. While the workers are busy a lease
    waits its turn in the broker, and a copy at every sweep would lengthen the queue it waits
    in; a lost message still goes again within twice its age, and a lease nobody claims
    expires (_expire_lease)."""
    if period <= 0:
        return True
    sweeps = int(age.total_seconds() / period)
    return sweeps >= 1 and sweeps & (sweeps - 1) == 0


def _first_due_per_cobot(now: dt.datetime) -> list[int]:
    """The first due job of each queue (a cobot's, a device's) that has nothing running,
    leaving out the jobs another case's func hold keeps waiting (the holding case's own may go).

    One statement that asks each queue for its head, a row per queue: the sweeper runs every
    few seconds however long the queues have grown (numbering every queued job to find each
    queue's first took 13 ms at 1000 queued; the database still sorts each queue's due jobs:
    bench/README.md, "Cobot queues").
    """
    return [job for job, _ in _queue_heads(now=now)]


@rows.Compiled
def _queue_heads(now: dt.datetime) -> QuerySet[Any, Any]:
    """_first_due_per_cobot's statement, compiled once: built by the ORM at each sweep it took
    8.6 ms, most of a sweep's time, against 2.5 ms compiled (bench/README.md)."""
    running = Job.objects.filter(state=JobState.RUNNING)
    due = Job.objects.filter(
        state=JobState.QUEUED, next_try_at__lte=now, case__status=CaseStatus.RUNNING
    ).order_by("queued_at", "id")
    heads = [
        queues.exclude(Exists(running.filter(**{field: OuterRef("pk")})))
        .annotate(
            job=Subquery(first.values("pk")[:1]), at=Subquery(first.values("queued_at")[:1])
        )
        .filter(job__isnull=False)
        .order_by()  # the union is ordered (SQLite allows no ORDER BY in its parts)
        .values_list("job", "at")
        for queues, field, first in (
            (Cobot.objects.all(), "cobot_id",
             due.filter(cobot_id=OuterRef("pk")).exclude(
                 Exists(_held_by_another_case(OuterRef("cobot_id"))))),
            (Device.objects.all(), "device_id", due.filter(device_id=OuterRef("pk"))),
        )
    ]  # fmt: skip
    return heads[0].union(heads[1], all=True).order_by("at", "job")


def _expire_lease(job_id: int, case_id: int) -> None:
    with transaction.atomic():
        case, job = lock_case_and_job(case_id, job_id)
        if (
            job.state != JobState.RUNNING
            or job.lease_expires_at is None
            or job.lease_expires_at >= timezone.now()
        ):
            return
        if _ended_with_case(case, job):
            return
        job.lease_expiries += 1
        if job.lease_expiries >= MAX_LEASE_EXPIRIES:
            job.state, job.ended_at = JobState.FAILED, timezone.now()
            job.save()
            events.open_incident(
                case, IncidentKind.LEASE_EXPIRED,
                f"Workers lost job {job.pk} ({job.work_item.label}) {job.lease_expiries} times; "
                "check the workers' logs, then retry, skip or cancel.",
                item=job.work_item,
            )  # fmt: skip
        else:
            job.state, job.next_try_at = JobState.QUEUED, timezone.now()
            job.save()
        case.save()
        _publish_queue(job)
        dispatch.send_on_commit(Task.RUN_JOB, job.pk)
