"""The engine's firing rule applied to a case's rows: what happens once a command is allowed.

Advancing (silent transitions, buffered messages, held completions), offering
and withdrawing work items, starting and completing tasks (an operator's and a
cobot's), queueing jobs, space constraints' interruptions, and the end of a
case. Each function expects the case row lock held (lock_case and
lock_operator_item take it) and leaves saving the case to its caller: the public
commands (services.py) and the workers (jobs.py, messages.py) lock and check
first. Lock order, everywhere: cobot row (a device's job: the device row), then case
row, then job row, then interruption row.
"""

from __future__ import annotations

import datetime as dt
import functools
import os
import socket
from collections import Counter
from collections.abc import Mapping
from typing import Any, cast

from django.conf import settings
from django.contrib.auth.models import User
from django.db.models import Exists, OuterRef, Q, QuerySet
from django.utils import timezone

from hrc.cases import dispatch, rows
from hrc.cases.choices import (
    COMMANDED_MODES,
    OPEN_CASE_STATUSES,
    OPEN_WORK_ITEM_STATES,
    CaseStatus,
    EventType,
    IncidentKind,
    InterruptionMode,
    JobState,
    Resolution,
    TimerState,
    WorkItemKind,
    WorkItemState,
)
from hrc.cases.dispatch import Task
from hrc.cases.events import open_incident, record_event
from hrc.cases.models import Case, CaseTimer, Incident, Interruption, Job, Message, WorkItem
from hrc.cases.nets import net_of
from hrc.cases.selectors import holding_work_items
from hrc.cobots.control import running_commands
from hrc.cobots.models import Cobot
from hrc.engine.commands import cobot_command
from hrc.engine.petri import Marking
from hrc.engine.runtime import (
    AreaRule,
    CaseNet,
    NotEnabled,
    Outgoing,
    RuntimeFault,
    apply_outputs,
    correlates,
    outgoing,
)
from hrc.engine.taskconfig import TaskConfig
from hrc.errors import Conflict, Invalid, NotAllowed, NotFound
from hrc.organisations.models import Membership, Team

# advance() repeats settle → messages → held completions until nothing changes;
# each round consumes a token or a message, so a sound net stops long before this.
MAX_ROUNDS = 10_000
# How long a message waits for a case to take it: one from outside unless it says otherwise,
# and every message a case sends.
MESSAGE_TTL_SECONDS = 3600
# What leasing a job changes on its row.
LEASED_FIELDS = ["state", "lease", "waiting_for", "held_by", "started_at", "lease_expires_at"]
# A timer's doorbell is sent only when it is due within this: Redis hands a message not
# acknowledged within an hour (its visibility timeout) to a worker again, so a doorbell held
# for days would come back every hour. The sweeper rings the later ones, a sweep late at most.
DOORBELL_HORIZON_SECONDS = 600


# The locks every writer takes first -------------------------------------------------


def lock_case(case_id: int) -> Case:
    """The case, its row locked until the transaction ends (its version not read: nets.net_of).
    Raises Case.DoesNotExist."""
    case = rows.fetch_one(Case, "id = %s", [case_id], lock="FOR NO KEY UPDATE")
    if case is None:
        raise Case.DoesNotExist(f"There is no case {case_id}.")
    return case


def lock_operator_item(item: WorkItem | int, user: User) -> tuple[Case, WorkItem]:
    """The case and an operator work item the user may perform, both locked, in one statement;
    the case and the user it is claimed by attached to the item.

    The case is found through the item and the user's active membership of its organisation
    in the statement that locks it: the organisations' wall costs the request no read of its
    own. The item is locked too, after its case (the project's lock order), so that both are
    read as they are once the locks are held, even by a statement that waited for them.
    """
    item_id: int = item.pk if isinstance(item, WorkItem) else item
    where, performable_sql = _operator_item_sql()
    found = rows.fetch_each_with(
        (Case, WorkItem), where, [user.pk, user.pk, item_id, user.pk], [performable_sql],
        lock="FOR NO KEY UPDATE",
    )  # fmt: skip
    if found is None:
        raise NotFound(f"There is no work item {item_id} in your organisations.")
    (case, item), (performable,) = cast(tuple[tuple[Case, WorkItem], tuple[bool]], found)
    check_operator_task(item)
    if not performable:
        raise NotAllowed(f"{item.label} is not offered to you.")
    # What the caller hands back (the API's answer) reads these; they are in hand.
    item.case = case
    if item.claimed_by_id == user.pk:
        item.claimed_by = user
    return case, item


@functools.cache
def _operator_item_sql() -> tuple[str, str]:
    """lock_operator_item's conditions in SQL: item %s and its case, whose organisation user
    %s is an active member of; whether the item is offered to user %s (a candidate, or in its
    team: selectors.performable_by's rule)."""
    items, cases = rows.table(WorkItem), rows.table(Case)
    members = rows.table(Membership)
    candidates = rows.table(WorkItem.candidates.through)
    teams = rows.table(Team.members.through)
    where = (
        f"{items}.id = %s AND {cases}.id = {items}.case_id AND EXISTS (SELECT 1 FROM {members} m "
        f"WHERE m.organisation_id = {cases}.organisation_id AND m.user_id = %s AND m.is_active)"
    )
    performable = (
        f"({items}.kind = '{WorkItemKind.OPERATOR.value}' AND (EXISTS (SELECT 1 FROM {candidates} c "
        f"WHERE c.workitem_id = {items}.id AND c.user_id = %s) OR EXISTS (SELECT 1 FROM {teams} t "
        f"JOIN {members} m ON m.id = t.membership_id "
        f"WHERE t.team_id = {items}.team_id AND m.user_id = %s)))"
    )
    return where, performable


def check_operator_task(item: WorkItem) -> None:
    """Conflict unless the work item is an operator's (a cobot's is the workers' to drive)."""
    if item.kind != WorkItemKind.OPERATOR:
        raise Conflict(f"{item.label} is done by a cobot, not by an operator.")


# The firing rule on the rows ---------------------------------------------------------


def advance(case: Case, net: CaseNet) -> None:
    """Fires what fires by itself and brings the work items in line with the marking.

    Silent transitions fire, buffered messages are taken, cobot tasks whose
    step is done complete once their func constraints allow; then the case
    completes, or timers are armed and disarmed, tasks that became startable
    are offered and those that stopped being startable are withdrawn. Call
    while holding the case row lock; the caller saves the case.
    """
    if case.status not in OPEN_CASE_STATUSES:
        return
    try:
        for _ in range(MAX_ROUNDS):
            fired = _settle(case, net)
            taken = take_buffered_message(case, net)
            held = _complete_held_steps(case, net)
            if not (fired or taken or held):
                break
    except RuntimeFault as fault:
        fail_case(case, str(fault))
        return
    marking = Marking(case.marking)
    if net.is_final(marking):
        end_case(case, CaseStatus.COMPLETED, EventType.CASE_COMPLETED, None, {})
        return
    arm_timers(case, net)
    if case.status == CaseStatus.RUNNING:
        _offer_and_withdraw(case, net, marking)


def _settle(case: Case, net: CaseNet) -> bool:
    before = Marking(case.marking)
    after, fired = net.settle(before, case.data)
    marking = before
    for transition in fired:
        before_one, marking = marking, net.transition(transition).fire(marking)
        case.marking = dict(marking)
        record_event(
            case, EventType.TRANSITION_FIRED, task=transition, before=before_one, after=marking
        )
        _cancel_emptied(case, net, transition)
        if transition in net.sends:
            send_message(case, _outgoing(case, net, transition), transition)
    case.marking = dict(after)
    return bool(fired)


def _complete_held_steps(case: Case, net: CaseNet) -> bool:
    """Completes cobot tasks whose step is done and whose func constraints now allow it."""
    if not net.holdable_tasks:
        return False  # no constraint can hold a completion: nothing is ever held
    done = False
    undecided = Incident.objects.filter(work_item=OuterRef("pk"), resolved_at__isnull=True)
    held = (
        WorkItem.objects.filter(
            case=case, task__in=net.holdable_tasks, state=WorkItemState.RUNNING,
            job__state=JobState.SUCCEEDED,
        )
        .exclude(Exists(undecided))  # outputs that did not map wait for a person
        .select_related("job")
    )  # fmt: skip
    for item in held:
        if net.can_complete(Marking(case.marking), item.task):
            done = _complete_step(case, net, item, item.job.result or {}) or done
            # Completed, or an incident that its outputs did not map: it holds the cobot no more.
            _end_hold(item.job)
    return done


def _offer_and_withdraw(case: Case, net: CaseNet, marking: Marking) -> None:
    startable = set(net.startable(marking))
    open_items = {item.task: item for item in open_work_items(case)}
    for task, item in open_items.items():
        if item.state != WorkItemState.RUNNING and task not in startable:
            _withdraw(case, item, "another task took its turn")
    for task in net.startable(marking):
        if task not in open_items:
            _offer(case, net, task)
    if (
        not startable
        and not open_items
        and not net.waiting_messages(marking)
        and not net.waiting_timers(marking)
    ):
        fail_case(
            case,
            f"The case cannot go on: nothing can start in marking {dict(marking)} "
            "(a guard that holds for no branch?).",
        )


def open_work_items(case: Case) -> list[WorkItem]:
    """The case's work items not yet ended, oldest first."""
    states = sorted(OPEN_WORK_ITEM_STATES)
    where = f"case_id = %s AND state IN ({', '.join(['%s'] * len(states))}) ORDER BY offered_at, id"
    return rows.fetch(WorkItem, where, [case.pk, *states])


def _offer(case: Case, net: CaseNet, task: str) -> WorkItem:
    config = net.tasks[task]
    actor = net.performers[task]
    binding = case.actor_mapping[actor]
    device_id = _device_of(binding, config)
    item = WorkItem(
        case=case, task=task, label=net.labels[task], actor=actor,
        kind=config.kind, instructions=config.instructions, team_id=binding.get("team"),
        # A device call is its device's work: the cobot's queue stays free meanwhile.
        cobot_id=None if device_id else binding.get("cobot"), device_id=device_id,
    )  # fmt: skip
    if config.kind == "operator":
        rows.insert(item)
        # A new item has no candidates yet: insert them in one statement.
        Candidate = WorkItem.candidates.through
        Candidate.objects.bulk_create(
            Candidate(workitem_id=item.pk, user_id=user_id) for user_id in binding.get("users", ())
        )
    else:
        _queue_job(case, net, item, config)  # the item with it
    record_event(case, EventType.TASK_OFFERED, item=item)
    return item


def _device_of(binding: Mapping[str, Any], config: TaskConfig) -> int | None:
    """The device a device call runs on (mapping.py resolved it at the start); None for another
    task, and for a call of a case started before devices had queues (its cobot runs it)."""
    if config.device is None:
        return None
    if "device" in binding:
        return int(binding["device"])
    device_id = binding.get("devices", {}).get(config.device.call.split(".")[0])
    return None if device_id is None else int(device_id)


def _queue_job(case: Case, net: CaseNet, item: WorkItem, config: TaskConfig) -> None:
    """Inserts the new item and its job, queued (or failed, when its command cannot be made)."""
    # A cobot task's actor maps to a cobot, a device call to a device (mapping.py).
    assert item.cobot_id is not None or item.device_id is not None
    now = timezone.now()
    job = Job(
        case=case, cobot_id=item.cobot_id, device_id=item.device_id, kind=config.kind,
        timeout=config.timeout, retries_left=config.retries, next_try_at=now, command={},
    )  # fmt: skip
    try:
        job.command = cobot_command(item.task, config, case.data)
    except RuntimeFault as fault:
        job.state, job.last_error = JobState.FAILED, str(fault)
    rows.insert_with(item, job, "work_item")
    if job.state == JobState.FAILED:
        open_incident(case, IncidentKind.CASE_FAULT, job.last_error, item=item)
        return
    jobs_queued_now(case).append(job)
    # The queue's doorbell, unless hand_over leased the job in this transaction (its message
    # goes to a worker instead) or saw a step running on the cobot (its worker leases the
    # next job once it is done: jobs._drive): asked of the rows in hand, after the commit.
    dispatch.send_on_commit_if(
        lambda: job.state == JobState.QUEUED and job.pk not in _behind_a_step(case),
        Task.RUN_JOB, job.pk,
    )  # fmt: skip


def jobs_queued_now(case: Case) -> list[Job]:
    """The jobs this transaction queued for the case, in order (hand_over's candidates)."""
    queued: list[Job] = case.__dict__.setdefault("_jobs_queued_now", [])
    return queued


def _behind_a_step(case: Case) -> set[int]:
    """The jobs this transaction queued behind a step it saw running on their cobot while it
    held the cobot's row (hand_over): that step's worker leases them, no doorbell needed."""
    behind: set[int] = case.__dict__.setdefault("_behind_a_step", set())
    return behind


def _withdraw(case: Case, item: WorkItem, why: str) -> None:
    _close(case, item, WorkItemState.WITHDRAWN)
    record_event(case, EventType.TASK_WITHDRAWN, item=item, detail={"why": why})


def _close(case: Case, item: WorkItem, state: WorkItemState) -> None:
    """Ends an open item that did not complete: its jobs not yet sent leave the queue, a func
    hold on its cobot ends, its open incidents are resolved as cancelled. A step on its cobot
    runs on (jobs.finish_job records how it ended)."""
    if item.state == WorkItemState.RUNNING and item.kind != WorkItemKind.OPERATOR:
        held = Job.objects.filter(work_item=item, state=JobState.SUCCEEDED).first()
        if held is not None:  # the item ends while its func constraint holds the cobot
            _end_hold(held)
    item.state, item.ended_at = state, timezone.now()
    rows.update(item, ["state", "ended_at"])
    Job.objects.filter(work_item=item, state__in=[JobState.QUEUED, JobState.FAILED]).update(
        state=JobState.CANCELLED, ended_at=item.ended_at
    )
    Incident.objects.filter(work_item=item, resolved_at__isnull=True).update(
        resolved_at=item.ended_at, resolution=Resolution.CANCEL
    )


def _cancel_emptied(case: Case, net: CaseNet, transition: str) -> None:
    """Cancels the running items whose task the firing of `transition` emptied (its `cancels`):
    an item counts while the marking's `running:<task>` has a token for it, the earliest
    started first. Items not started whose input it emptied are withdrawn, saying so. Call
    right after the firing, holding the case row lock."""
    resets = set(net.transition(transition).resets)
    if not resets:
        return
    marking = Marking(case.marking)
    counted: Counter[str] = Counter()
    items = WorkItem.objects.filter(case=case, state__in=OPEN_WORK_ITEM_STATES)
    for item in items.order_by("started_at", "id"):
        if item.state == WorkItemState.RUNNING:
            counted[item.task] += 1
            if counted[item.task] > marking.get(f"running:{item.task}"):
                _cancel(case, item, transition)
        elif not net.can_start(marking, item.task) and resets & _inputs(net, item.task):
            _withdraw(case, item, f"{net.labels.get(transition, transition)} cancelled it")


def _inputs(net: CaseNet, task: str) -> set[str]:
    return {place for place, _ in net.transition(f"start:{task}").pre}


def _cancel(case: Case, item: WorkItem, by: str) -> None:
    """Ends a running item the transition `by` cancelled. An operator's leaves the tablets; a
    cobot's step not yet sent leaves the queue, one on the cobot is not stopped (a person stops
    a cobot). What it kept out of a shared area goes on, as when it completes; a cobot it paused
    or slowed stays so until a person says the area is clear (confirm_left_area)."""
    _close(case, item, WorkItemState.CANCELLED)
    # The model, not the operator, ended the task: the operator may still be in the area. A
    # pause of its own cobot stays until the task beside it ends: that step is not over.
    _end_interruptions(case, Q(by_work_item=item) & ~Q(mode__in=COMMANDED_MODES))
    presence = Q(by_work_item=item, mode__in=COMMANDED_MODES, ended_at__isnull=True)
    detail: dict[str, Any] = {"by": by}
    if item.kind == WorkItemKind.OPERATOR and Interruption.objects.filter(presence).exists():
        detail["in_area"] = True  # the tablet asks its operator to say when they have left
    record_event(case, EventType.TASK_CANCELLED, item=item, detail=detail)


def end_presence(case: Case, item: WorkItem) -> bool:
    """Ends the pauses and slowdowns a cancelled item's operator caused, once a person says
    the operator has left the area; whether any was still open. Call holding the case row lock."""
    which = Q(by_work_item=item, mode__in=COMMANDED_MODES)
    if not Interruption.objects.filter(which, case=case, ended_at__isnull=True).exists():
        return False
    _end_interruptions(case, which)
    return True


def start_task(case: Case, net: CaseNet, item: WorkItem, user: User | None) -> None:
    """Fires the task's start; pauses or slows the cobots it shares a space with (or itself, a
    step starting slowly beside an operator). Raises NotEnabled."""
    before = Marking(case.marking)
    after = net.start(before, item.task)
    case.marking = dict(after)
    item.state, item.started_at = WorkItemState.RUNNING, timezone.now()
    record_event(case, EventType.TASK_STARTED, item=item, user=user, before=before, after=after)
    if item.task in net.space_tasks:
        _interrupt_shared_space(case, net, item)


def complete_task(
    case: Case,
    net: CaseNet,
    item: WorkItem,
    result: Mapping[str, Any],
    user: User | None,
) -> None:
    """Fires the task's completion and maps its outputs into the case data. Raises NotEnabled."""
    before = Marking(case.marking)
    after = net.complete(before, item.task)
    try:
        case.data = apply_outputs(net.tasks[item.task], item.task, result, case.data)
        message = _outgoing(case, net, item.task) if item.task in net.sends else None
    except RuntimeFault as fault:
        raise Invalid(str(fault)) from None
    case.marking = dict(after)
    item.state, item.ended_at = WorkItemState.COMPLETED, timezone.now()
    item.result, item.completed_by = dict(result), user
    rows.update(item, ["state", "ended_at", "result", "completed_by", "started_at"])
    record_event(case, EventType.TASK_COMPLETED, item=item, user=user, before=before, after=after)
    if message is not None:
        send_message(case, message, item.task)
    if item.task in net.space_tasks:  # only a space constraint's tasks are ever interrupted
        _end_interruptions(case, Q(work_item=item) | Q(by_work_item=item))


def start_cobot_task(case: Case, net: CaseNet, item: WorkItem) -> None:
    """Starts a cobot task as its cobot takes the job (jobs.lease_next_job).

    Call while holding the case row lock, with the start enabled; the caller saves the case,
    and with it the item when its start changes nothing else (advance_after_start): then
    nothing reads the item before that save.
    """
    start_task(case, net, item, None)
    if item.task in net.starts_alone:
        case.keep(item, ["state", "started_at"])
        return
    rows.update(item, ["state", "started_at"])
    advance(case, net)


def advance_after_start(case: Case, net: CaseNet, task: str) -> None:
    """advance, after `task` has started, unless its start can change nothing else (the net's
    starts_alone: the work items already match the marking, and no other transition's
    enabling moved); that saves a hot path's start the read of the open work items."""
    if task not in net.starts_alone:
        advance(case, net)


def lease_job(case: Case, net: CaseNet, job: Job, now: dt.datetime, *, held_by: str) -> None:
    """Leases the job (its next lease number), starting its task when it is only offered (the
    cobot or device taking the job is the moment the task starts); the caller's case.save()
    writes the job with the case.
    `held_by`: the worker's host:pid, or "" for a lease a worker is yet to claim (hand_over).
    Call holding the case's lock and the job's queue's, once nothing keeps the job waiting."""
    if job.work_item.state == WorkItemState.OFFERED:
        start_cobot_task(case, net, job.work_item)
    job.state, job.lease, job.waiting_for = JobState.RUNNING, job.lease + 1, ""
    job.held_by = held_by
    job.started_at = job.started_at or now
    job.lease_expires_at = now + dt.timedelta(seconds=job.timeout + settings.HRC_JOB_LEASE_MARGIN)
    case.keep(job, LEASED_FIELDS)  # nothing reads the job before the case is saved


def worker_name() -> str:
    """What a lease's held_by says of this process."""
    return f"{socket.gethostname()}:{os.getpid()}"


def hand_over(case: Case, net: CaseNet) -> None:
    """Leases each step this transaction queued whose cobot is free now, in this transaction:
    the completion that enabled a step hands it to a worker in one hop (jobs.run_leased_job
    claims the lease its message carries and sends the step), instead of a doorbell, then a
    worker's lease in a transaction of its own.

    Free: no other job queued or running on the cobot, no STOP, no pause for an operator, no
    other case's func hold, no person's command under way, and the cobot's row not locked: a
    worker holding it is leasing, and will wait for this case's lock, so the row is taken with
    SKIP LOCKED and this never waits (the workers' lock order is cobot, then case). A step of a
    space constraint's task, and every other case, stays queued for its doorbell. Call after
    advance, holding the case's lock; the caller saves the case."""
    if case.status != CaseStatus.RUNNING:
        return
    marking, now = Marking(case.marking), timezone.now()
    for job in jobs_queued_now(case):
        item = job.work_item
        if (
            job.state != JobState.QUEUED
            or job.kind != WorkItemKind.STEP
            or job.cobot_id is None
            or item.task in net.space_tasks  # kept out or slowed: the worker's lease decides
            or item.state != WorkItemState.OFFERED
            or not net.can_start(marking, item.task)
        ):
            continue
        cobot = _take_free_cobot(job)
        if cobot is None:
            continue
        if cobot["running"]:
            # Its worker leases the next job after its commit, taking this row's lock first,
            # so it sees this job: the worker's lease is the doorbell (jobs._drive).
            _behind_a_step(case).add(job.pk)
        if not cobot["free"]:
            continue
        lease_job(case, net, job, now, held_by="")
        dispatch.send_on_commit(Task.RUN_LEASED_JOB, leased_message(job, cobot, cobot["speed_due"]))
        marking = Marking(case.marking)


# What a leased job's message says of its cobot (_take_free_cobot reads it, Lease takes it).
COBOT_FIELDS = ("id", "organisation_id", "name", "endpoint", "credentials_source")


def _take_free_cobot(job: Job) -> dict[str, Any] | None:
    """Locks the job's cobot's row (SKIP LOCKED): its COBOT_FIELDS; `free`, whether it may take
    the job now; `running`, whether a step runs on it; `speed_due`, whether a speed change
    waits to be sent before its next step. None when another session holds the row."""
    assert job.cobot_id is not None  # a step's job is on a cobot
    found = _cobot_for(cobot=job.cobot_id, job=job.pk, case=job.case_id, now=timezone.now())
    if not found:
        return None
    row = found[0]
    stopped_at, running, ahead, paused, held, commanded, speed_due = row[len(COBOT_FIELDS) :]
    return dict(zip(COBOT_FIELDS, row, strict=False)) | {
        "free": not (stopped_at or running or ahead or paused or held or commanded),
        "running": running, "speed_due": speed_due,
    }  # fmt: skip


@rows.Compiled
def _cobot_for(cobot: int, job: int, case: int, now: dt.datetime) -> QuerySet[Cobot, Any]:
    here = OuterRef("pk")
    others = Job.objects.filter(cobot=here).exclude(pk=job)
    return (
        Cobot.objects.select_for_update(of=("self",), no_key=True, skip_locked=True)
        .filter(pk=cobot)
        .annotate(
            running=Exists(others.filter(state=JobState.RUNNING)),
            ahead=Exists(others.filter(state=JobState.QUEUED)),
            paused=Exists(unsettled_pauses(here)),
            held=Exists(holding_work_items().filter(cobot_id=here).exclude(case_id=case)),
            commanded=Exists(running_commands(now).filter(cobot=here)),
            speed_due=Exists(speed_changes_due(here)),
        )
        .values_list(
            *COBOT_FIELDS, "stopped_at", "running", "ahead", "paused", "held", "commanded",
            "speed_due",
        )
    )  # fmt: skip


def leased_message(job: Job, cobot: Mapping[str, Any], speed_due: bool) -> dict[str, Any]:
    """What a worker needs to drive a job leased for it without reading it again: the lease,
    the command, the cobot's COBOT_FIELDS (`cobot`, or cobot_fields) and whether a speed
    change waits to be sent before the step (jobs.Lease.from_message)."""
    return {
        "job": job.pk, "case": job.case_id, "lease": job.lease, "attempt": job.attempt,
        "kind": job.kind, "command": job.command, "timeout": job.timeout,
        "cobot": {**{field: cobot[field] for field in COBOT_FIELDS}, "speed_due": speed_due},
    }  # fmt: skip


def cobot_fields(cobot: Cobot) -> dict[str, Any]:
    """The cobot's COBOT_FIELDS, as leased_message takes them."""
    return {field: getattr(cobot, field) for field in COBOT_FIELDS}


def unsettled_pauses(cobot: Cobot | int | OuterRef) -> QuerySet[Interruption]:
    """The pauses that keep the cobot from taking a step: not yet over, or not yet resumed. A
    slowed cobot takes steps (its worker sets their speed first)."""
    return Interruption.objects.filter(cobot=cobot, mode=InterruptionMode.PAUSE).filter(
        Q(ended_at__isnull=True) | Q(paused_at__isnull=False, resumed_at__isnull=True)
    )


def speed_changes_due(cobot: Cobot | int | OuterRef) -> QuerySet[Interruption]:
    """The slowdowns of the cobot whose command or undoing is yet to be sent: a slowdown that
    ended and has not been restored, or one still open and not yet sent."""
    return Interruption.objects.filter(cobot=cobot, mode=InterruptionMode.SLOW).filter(
        Q(ended_at__isnull=False, resumed_at__isnull=True)
        | Q(ended_at__isnull=True, paused_at__isnull=True)
    )


def complete_cobot_task(
    case: Case, net: CaseNet, item: WorkItem, result: Mapping[str, Any]
) -> None:
    """Completes a cobot task whose step is done, unless a func constraint still holds it
    (then `advance` completes it once the constraint allows).

    Call while holding the case row lock, with the item running; the caller saves the case.
    """
    if net.can_complete(Marking(case.marking), item.task):
        _complete_step(case, net, item, result)
    advance(case, net)


def _complete_step(case: Case, net: CaseNet, item: WorkItem, result: Mapping[str, Any]) -> bool:
    """Completes a cobot task whose step is done; an incident when its outputs do not map.

    The step ran and is not sent again: a person skips the task with the
    outputs it should have given, or cancels the case.
    """
    try:
        complete_task(case, net, item, result, None)
    except Invalid as fault:
        open_incident(
            case, IncidentKind.CASE_FAULT,
            f"{item.label} ran, but its outputs cannot go into the case data: {fault}", item=item,
        )  # fmt: skip
        return False
    return True


# Messages, interruptions, doorbells -----------------------------------------------------


def take_buffered_message(case: Case, net: CaseNet, only: int | None = None) -> bool:
    """Fires a waiting message transition with the oldest matching unexpired message, if any.

    Call while holding the case row lock. Returns whether a message was taken.
    """
    waiting = net.waiting_messages(Marking(case.marking))
    if not waiting:
        return False
    names = {config.name for _, config in waiting}
    messages = Message.objects.select_for_update(skip_locked=True).filter(
        organisation_id=case.organisation_id, name__in=names,
        consumed_at__isnull=True, expires_at__gt=timezone.now(),
    )  # fmt: skip
    if only is not None:
        messages = messages.filter(pk=only)
    for message in messages.order_by("received_at", "id")[:100]:
        for transition, config in waiting:
            if config.name == message.name and correlates(
                config, case.data, message.correlation, case_names(case)
            ):
                before = Marking(case.marking)
                after = net.receive(before, transition)
                case.marking = dict(after)
                case.data = {**case.data, **message.payload}
                message.case, message.transition = case, transition
                message.consumed_at = timezone.now()
                message.save(update_fields=["case", "transition", "consumed_at"])
                record_event(
                    case, EventType.MESSAGE_RECEIVED, task=transition, before=before, after=after,
                    detail={"message": message.message_id, "name": message.name},
                )  # fmt: skip
                _cancel_emptied(case, net, transition)
                if transition in net.sends:  # a RuntimeFault fails the case (advance, take)
                    send_message(case, _outgoing(case, net, transition), transition)
                return True
    return False


def take_message(case: Case, net: CaseNet, message_pk: int) -> bool:
    """Offers the case one message (a delivery): when a waiting message transition takes it,
    the case advances. Call while holding the case row lock. Returns whether it was taken."""
    try:
        taken = take_buffered_message(case, net, only=message_pk)
    except RuntimeFault as fault:  # what the receiving transition sends failed
        fail_case(case, str(fault))
        return True
    if taken:
        advance(case, net)
    return taken


# Timers ---------------------------------------------------------------------------------


def arm_timers(case: Case, net: CaseNet) -> None:
    """Arms each timer transition the marking enables and no armed timer stands for (due after
    its duration times the case's timer scale; its doorbell rings then), and disarms the armed
    ones whose transition it no longer enables. One that stays enabled keeps its due time.
    Each is a case event, so a tablet keeps the timers a case waits for from its deltas alone.
    Call while holding the case row lock; the caller saves the case."""
    if not net.timers:
        return  # most patterns: no query
    waiting = dict(net.waiting_timers(Marking(case.marking)))
    now = timezone.now()
    for timer in CaseTimer.objects.filter(case=case, state=TimerState.ARMED):
        if waiting.pop(timer.transition, None) is None:
            timer.state, timer.ended_at = TimerState.DISARMED, now
            timer.save(update_fields=["state", "ended_at"])
            record_event(case, EventType.TIMER_DISARMED, task=timer.transition,
                         detail=_timer_detail(timer))  # fmt: skip
    for transition, milliseconds in waiting.items():
        seconds = milliseconds / 1000 * case.timer_scale
        timer = CaseTimer.objects.create(
            case=case, transition=transition, label=net.labels.get(transition, transition),
            due_at=now + dt.timedelta(seconds=seconds),
        )  # fmt: skip
        record_event(case, EventType.TIMER_ARMED, task=transition, detail=_timer_detail(timer))
        ring_timer_on_commit(timer)


def _timer_detail(timer: CaseTimer) -> dict[str, str]:
    """What a timer event says of its timer: enough for a tablet to show or drop its line."""
    return {
        "transition": timer.transition,
        "label": timer.label or timer.transition,
        "due_at": timer.due_at.isoformat(),
    }


def ring_timer_on_commit(timer: CaseTimer) -> None:
    """Rings the timer's doorbell at its due time once this transaction commits; one due beyond
    DOORBELL_HORIZON_SECONDS is left to the sweeper (timers.sweep_timers)."""
    seconds = max((timer.due_at - timezone.now()).total_seconds(), 0.0)
    if seconds <= DOORBELL_HORIZON_SECONDS:
        dispatch.send_on_commit(Task.RING_TIMER, timer.pk, countdown=seconds)


def fire_timer(case: Case, net: CaseNet, timer: CaseTimer) -> None:
    """Fires the timer's transition, then advances the case. Raises NotEnabled when the marking
    does not enable it. Call while holding the case row lock, with the timer armed and due;
    the caller saves the case."""
    before = Marking(case.marking)
    after = net.ring(before, timer.transition)
    case.marking = dict(after)
    timer.state, timer.ended_at = TimerState.FIRED, timezone.now()
    timer.save(update_fields=["state", "ended_at"])
    record_event(
        case, EventType.TIMER_FIRED, task=timer.transition, before=before, after=after,
        detail={**_timer_detail(timer), "armed_at": timer.armed_at.isoformat()},
    )  # fmt: skip
    _cancel_emptied(case, net, timer.transition)
    if timer.transition in net.sends:
        try:
            send_message(case, _outgoing(case, net, timer.transition), timer.transition)
        except RuntimeFault as fault:
            fail_case(case, str(fault))
            return
    advance(case, net)


def disarm_timers(case: Case) -> None:
    """Disarms the case's armed timers (it ended), each a case event as in arm_timers.
    Call while holding the case row lock; the caller saves the case."""
    now = timezone.now()
    for timer in CaseTimer.objects.filter(case=case, state=TimerState.ARMED):
        timer.state, timer.ended_at = TimerState.DISARMED, now
        timer.save(update_fields=["state", "ended_at"])
        record_event(case, EventType.TIMER_DISARMED, task=timer.transition,
                     detail=_timer_detail(timer))  # fmt: skip


def case_names(case: Case) -> dict[str, Any]:
    """What message expressions read as `case`."""
    return {"id": case.pk, "reference": case.reference}


def _outgoing(case: Case, net: CaseNet, transition: str) -> Outgoing:
    return outgoing(transition, net.sends[transition], case.data, case_names(case))


def send_message(case: Case, message: Outgoing, transition: str) -> Message:
    """Puts the message a case sends in the outbox: a row that commits with the firing or not at
    all. Its id is the case's, the transition's and the event's number, so a transaction run
    again after a rollback writes the same id and one that committed can never be repeated.
    Another process of this case takes it in advance()'s loop; other cases after commit."""
    message_id = f"case:{case.pk}:{transition}:{case.last_seq + 1}"  # the event's number
    record_event(case, EventType.MESSAGE_SENT, task=transition, detail={
        "message": message_id, "name": message.name, "correlation": message.correlation,
    })  # fmt: skip
    row = Message.objects.create(
        organisation_id=case.organisation_id, message_id=message_id, name=message.name,
        correlation=message.correlation, payload=message.payload,
        expires_at=timezone.now() + dt.timedelta(seconds=MESSAGE_TTL_SECONDS),
        sent_from_case=case, sent_from_transition=transition,
    )  # fmt: skip
    dispatch.send_on_commit(Task.DELIVER_MESSAGE, row.pk)
    return row


def kept_out_by(case: Case, net: CaseNet, item: WorkItem) -> tuple[AreaRule, WorkItem] | None:
    """The space rule and the running task that keep `item` from starting now (an operator is
    refused, a cobot's step waits); None when nothing in a shared area does."""
    for rule in net.space_rules(item.task):
        if rule.keeps_out and rule.held == item.task:
            occupant = _running(case, rule.by)
            if occupant is not None:
                return rule, occupant
    return None


def keep_out(case: Case, item: WorkItem, rule: AreaRule, occupant: WorkItem) -> str:
    """Records that `item` is kept out of the area `occupant` works in (once while it lasts:
    the interruption ends when the occupant completes); returns why, naming the task in the
    area and who does it. Call while holding the case row lock; the caller saves the case."""
    already = Interruption.objects.filter(
        case=case, work_item=item, by_work_item=occupant, ended_at__isnull=True
    ).exists()
    if not already:
        interruption = Interruption.objects.create(
            case=case, work_item=item, by_work_item=occupant, cobot_id=item.cobot_id,
            mode=InterruptionMode.REFUSED if rule.mode == "refused" else InterruptionMode.WAIT,
        )  # fmt: skip
        record_event(case, EventType.TASK_KEPT_OUT, item=item, detail=_detail(interruption, occupant))  # fmt: skip
    return (
        f"{occupant.label} ({_performer(occupant)}) is in the shared area; {item.label} "
        "can start once it is done (space constraint)."
    )


def _interrupt_shared_space(case: Case, net: CaseNet, entering: WorkItem) -> None:
    for rule in net.space_rules(entering.task):
        if rule.keeps_out:
            continue  # checked before the start: kept_out_by
        other = _running(case, rule.by if rule.held == entering.task else rule.held)
        if other is None:
            continue  # not running: nothing shares the area now
        held, by = (entering, other) if rule.held == entering.task else (other, entering)
        if held.cobot_id is None:
            continue
        interruption = Interruption.objects.create(
            case=case, work_item=held, by_work_item=by, cobot_id=held.cobot_id, mode=rule.mode
        )
        record_event(case, EventType.TASK_INTERRUPTED, item=held, detail=_detail(interruption, by))
        if held is not entering:
            # A step starting slowly is slowed by its worker before it goes (jobs._execute).
            dispatch.send_on_commit(Task.INTERRUPT_COBOT, interruption.pk)


def _running(case: Case, task: str) -> WorkItem | None:
    return (
        WorkItem.objects.filter(case=case, task=task, state=WorkItemState.RUNNING)
        .select_related("claimed_by", "cobot")
        .first()
    )


def _performer(item: WorkItem) -> str:
    """Who does the item: its operator's user name, or its cobot's name."""
    if item.cobot is not None:
        return item.cobot.name
    return item.claimed_by.username if item.claimed_by is not None else item.actor


def _detail(interruption: Interruption, by: WorkItem) -> dict[str, Any]:
    return {
        "interruption": interruption.pk, "by": by.task, "by_actor": by.actor,
        "by_performer": _performer(by), "mode": interruption.mode,
    }  # fmt: skip


def _end_interruptions(case: Case, which: Q) -> None:
    for interruption in Interruption.objects.filter(which, case=case, ended_at__isnull=True):
        interruption.ended_at = timezone.now()
        interruption.save(update_fields=["ended_at"])
        if interruption.mode not in COMMANDED_MODES:
            # Kept out: the task may start now (its start is its event); a waiting step goes.
            if interruption.mode == InterruptionMode.WAIT:
                _ring_for_waiting_step(interruption.work_item_id)
            continue
        seconds = (interruption.ended_at - interruption.started_at).total_seconds()
        record_event(case, EventType.TASK_RESUMED, item=interruption.work_item,
                detail={"interruption": interruption.pk, "seconds": round(seconds, 3)})  # fmt: skip
        dispatch.send_on_commit(Task.RESUME_COBOT, interruption.pk)


def _ring_for_waiting_step(item_id: int) -> None:
    """The step that waited for the area may go: its cobot's doorbell rings after the commit."""
    job_id = (
        Job.objects.filter(work_item_id=item_id, state=JobState.QUEUED)
        .values_list("pk", flat=True)
        .first()
    )
    if job_id is not None:
        dispatch.send_on_commit(Task.RUN_JOB, job_id)


def _end_hold(job: Job) -> None:
    """The cobot a func hold reserved for this case is free once this transaction commits: its
    next job goes now, not at the next sweep. Held items end only by completing (advance's
    held completions, which a skip or a message reaches too) or by withdrawal (the case ends)."""
    ring_for_next_on_commit(job)


def ring_for_next_on_commit(job: Job) -> None:
    """Rings the doorbell of the job's queue after commit: its device's for a device call,
    else its cobot's (ring_for_next_job_on_commit)."""
    if job.device_id is None:
        ring_for_next_job_on_commit(job.pk, job.cobot_id)  # type: ignore[arg-type]
        return
    device_id = job.device_id

    def queued() -> bool:
        return Job.objects.filter(device_id=device_id, state=JobState.QUEUED).exists()

    dispatch.send_on_commit_if(queued, Task.RUN_JOB, job.pk)


def ring_for_next_job_on_commit(job_id: int, cobot_id: int) -> None:
    """Rings the doorbell of `job_id`'s cobot once this transaction has committed, if a job is
    queued for the cobot then: most often none is, and a doorbell would cost a task and a
    transaction to find nothing. Asked after the commit, so none is missed: a job queued
    meanwhile rang its own doorbell, which found the cobot busy, after it had committed."""

    dispatch.send_on_commit_if(lambda: bool(_queued_on(cobot=cobot_id)), Task.RUN_JOB, job_id)


@rows.Compiled
def _queued_on(cobot: int) -> QuerySet[Job, Any]:  # asked after each step: compiled once
    return Job.objects.filter(cobot_id=cobot, state=JobState.QUEUED).values_list("pk")[:1]


def ring_for_due_timers_on_commit(case: Case) -> None:
    """Rings the doorbell of each armed timer of the case that is due (it waited while the case
    was suspended)."""
    due = CaseTimer.objects.filter(case=case, state=TimerState.ARMED, due_at__lte=timezone.now())
    for timer in due:
        ring_timer_on_commit(timer)


def ring_for_queued_jobs_on_commit(case: Case) -> None:
    """Rings the doorbell of each cobot the case has queued work for."""
    for job_id in Job.objects.filter(case=case, state=JobState.QUEUED).values_list("pk", flat=True):
        dispatch.send_on_commit(Task.RUN_JOB, job_id)


# Incidents resolved, and case endings --------------------------------------------------


def retry_job(case: Case, net: CaseNet, item: WorkItem, again: bool) -> None:
    """Queues the item's job again with its retries restored; `again` gives the step a new
    token, so a step that ran once runs once more. Conflict when there is no job or it runs."""
    job = Job.objects.select_for_update().filter(work_item=item).first()
    if job is None:
        raise Conflict(f"{item.label} is an operator task: there is nothing to retry.")
    if job.state == JobState.RUNNING:
        raise Conflict(f"{item.label} is running again already.")
    command = (
        cobot_command(item.task, net.tasks[item.task], case.data)
        if job.state == JobState.FAILED and not job.command
        else job.command
    )
    job.command = command
    job.state, job.retries_left, job.lease_expiries = (
        JobState.QUEUED,
        net.tasks[item.task].retries,
        0,
    )
    job.next_try_at, job.last_error = timezone.now(), ""
    # A person checked the device and asks for the call: it goes out once more. (By itself,
    # a call that may have gone out is never sent again: device_jobs, jobs._call_device.)
    job.sent_at = None
    if again:
        job.attempt += 1
    job.save()
    dispatch.send_on_commit(Task.RUN_JOB, job.pk)


def skip_task(case: Case, net: CaseNet, item: WorkItem, outputs: dict[str, Any], by: User) -> None:
    """Completes the item with `outputs` as if its step had given them (starting it first when it
    has not started); its unfinished jobs are cancelled. Conflict when the marking forbids it."""
    Job.objects.filter(work_item=item).exclude(state=JobState.SUCCEEDED).update(
        state=JobState.CANCELLED, ended_at=timezone.now()
    )
    if item.state != WorkItemState.RUNNING:
        try:
            start_task(case, net, item, by)
        except NotEnabled as refused:
            raise Conflict(f"{item.label} cannot be skipped now: {refused}") from None
    try:
        complete_task(case, net, item, outputs, by)
    except NotEnabled as refused:
        raise Conflict(f"{item.label} cannot be skipped now: {refused}") from None
    advance(case, net)


def end_case(case: Case, status: str, event: str, by: User | None, detail: dict[str, Any]) -> None:
    """Ends the case with `status`: open work is withdrawn, its interruptions end."""
    for item in open_work_items(case):
        _withdraw(case, item, f"the case is {status}")
    net = net_of(case)
    if net.space_tasks:  # only a space constraint's tasks are ever interrupted
        _end_interruptions(case, Q())
    if net.timers:
        disarm_timers(case)
    case.status, case.ended_at = status, timezone.now()
    record_event(case, event, user=by, detail=detail)


def end_as_cancelled(case: Case, by: User | None, detail: dict[str, Any]) -> None:
    end_case(case, CaseStatus.CANCELLED, EventType.CASE_CANCELLED, by, detail)


def fail_case(case: Case, message: str) -> None:
    open_incident(case, IncidentKind.CASE_FAULT, message)
    end_case(case, CaseStatus.FAILED, EventType.CASE_FAILED, None, {"message": message})
