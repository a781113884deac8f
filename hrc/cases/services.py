"""The public commands on a case: lock, check, then progress (the firing rule on the rows).

Each holds the case row lock for its whole transaction, so two tablets, a worker and a
message never change one case at once. Refusals belong to hrc.errors' family, each with the HTTP status the
API answers: Conflict (409, it has moved on), NotAllowed (403), Invalid (400).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from django.contrib.auth.models import User
from django.db import transaction
from django.utils import timezone

from hrc.cases import events, progress
from hrc.cases.choices import (
    OPEN_CASE_STATUSES,
    OPEN_WORK_ITEM_STATES,
    CaseStatus,
    EventType,
    Resolution,
    WorkItemKind,
    WorkItemState,
)
from hrc.cases.events import record_event
from hrc.cases.mapping import resolve_actor_mapping
from hrc.cases.models import Case, Incident, WorkItem
from hrc.cases.nets import case_net, net_of
from hrc.cases.progress import check_operator_task as check_operator_task  # the API asks it too
from hrc.cases.selectors import performers_of
from hrc.engine.forms import form_problems
from hrc.engine.runtime import CaseNet, NotEnabled
from hrc.engine.startdata import check_start_data
from hrc.errors import Conflict, Invalid
from hrc.patterns.models import PatternVersion

# A start form's "count": enough for a shift's batch, not a load test by accident.
MAX_CASES_AT_ONCE = 50
REFERENCE_LENGTH = Case._meta.get_field("reference").max_length or 100


def start_case(
    version: PatternVersion,
    *,
    started_by: User | None,
    actor_mapping: Mapping[str, Any] | None = None,
    data: Mapping[str, Any] | None = None,
    reference: str = "",
    timer_scale: float = 1.0,
) -> Case:
    """Starts a case of a published version; the mapping overrides the version's defaults per actor,
    `data` the pattern's initial data per key; its timers wait their duration times `timer_scale`
    (below 1 in a simulation). Invalid when the version is retired, an actor is unmapped or
    mapped outside the organisation, or a data key is not the pattern's or its type's.
    """
    return start_cases(
        version, started_by=started_by, actor_mapping=actor_mapping, data=data,
        reference=reference, count=1, timer_scale=timer_scale,
    )[0]  # fmt: skip


def start_cases(
    version: PatternVersion,
    *,
    started_by: User | None,
    actor_mapping: Mapping[str, Any] | None = None,
    data: Mapping[str, Any] | None = None,
    reference: str = "",
    count: int = 1,
    timer_scale: float = 1.0,
) -> list[Case]:
    """Starts `count` cases alike, all or none (start_case's checks, once)."""
    if version.retired_at is not None:
        raise Invalid.at("version", f"{version} is retired: it starts no new cases.")
    if not 1 <= count <= MAX_CASES_AT_ONCE:
        raise Invalid.at("count", f"Start between 1 and {MAX_CASES_AT_ONCE} cases at once.")
    if len(reference) > REFERENCE_LENGTH:
        raise Invalid.at("reference", f"The reference is longer than {REFERENCE_LENGTH} characters.")  # fmt: skip
    net = case_net(version)
    organisation = version.pattern.organisation
    mapping = {**(version.default_actor_mapping or {}), **(actor_mapping or {})}
    mapping = resolve_actor_mapping(net.pattern, organisation, mapping)
    if data is not None and not isinstance(data, Mapping):
        raise Invalid.at("data", "The case data must be a JSON object.")
    for key, problem in check_start_data(net.initial_data(), data or {}).items():
        raise Invalid.at(f"data.{key}", problem)
    cases = []
    with transaction.atomic():
        for _ in range(count):
            case = Case.objects.create(
                organisation=organisation, version=version, marking=dict(net.initial),
                data={**net.initial_data(), **(data or {})},  # the pattern's `data`, then the case's
                actor_mapping=mapping, started_by=started_by, reference=reference,
                timer_scale=timer_scale,
            )  # fmt: skip
            case = progress.lock_case(case.pk)
            case.version = version  # in hand: its callers read it
            record_event(case, EventType.CASE_STARTED, user=started_by, after=net.initial)
            progress.advance(case, net)
            case.save()
            cases.append(case)
    return cases


def set_default_actor_mapping(
    version: PatternVersion, mapping: Mapping[str, Any]
) -> PatternVersion:
    """Sets who performs each actor in the version's cases unless a case says otherwise.

    Raises Invalid as start_case does. Only this field of a version ever changes.
    """
    organisation = version.pattern.organisation
    resolved = resolve_actor_mapping(case_net(version).pattern, organisation, mapping)
    PatternVersion.objects.filter(pk=version.pk).update(default_actor_mapping=resolved)
    version.default_actor_mapping = resolved
    return version


def cancel_case(case: Case, *, by: User | None, reason: str = "") -> Case:
    """Cancels an open case: open work is withdrawn and queued jobs are cancelled.

    A step already running on a cobot finishes (the cobot is not stopped by
    this); its result is then ignored. Raises Conflict when the case has ended.
    """
    with transaction.atomic():
        case = progress.lock_case(case.pk)
        _check_open(case)
        progress.end_as_cancelled(case, by, {"reason": reason})
        case.save()
    return case


def suspend_case(case: Case, *, by: User | None) -> Case:
    """Stops offering and dispatching new work; tasks already running may finish."""
    with transaction.atomic():
        case = progress.lock_case(case.pk)
        if case.status != CaseStatus.RUNNING:
            raise Conflict(f"Case {case.pk} is {case.status}, not running: it cannot be suspended.")
        case.status = CaseStatus.SUSPENDED
        record_event(case, EventType.CASE_SUSPENDED, user=by)
        case.save()
    return case


def resume_case(case: Case, *, by: User | None) -> Case:
    with transaction.atomic():
        case = progress.lock_case(case.pk)
        if case.status != CaseStatus.SUSPENDED:
            raise Conflict(f"Case {case.pk} is {case.status}, not suspended.")
        case.status = CaseStatus.RUNNING
        record_event(case, EventType.CASE_RESUMED, user=by)
        progress.advance(case, net_of(case))
        progress.ring_for_queued_jobs_on_commit(case)
        progress.ring_for_due_timers_on_commit(case)
        case.save()
    return case


def claim_work_item(item: WorkItem | int, *, user: User) -> WorkItem:
    """Takes an offered operator task for `user`; Conflict when someone else has it."""
    with transaction.atomic():
        case, item = progress.lock_operator_item(item, user)
        if item.state != WorkItemState.OFFERED:
            raise Conflict(_moved_on(item, "claimed"))
        item.state, item.claimed_by = WorkItemState.CLAIMED, user
        item.save(update_fields=["state", "claimed_by"])
        record_event(case, EventType.TASK_CLAIMED, item=item, user=user)
        case.save()
    return item


def unclaim_work_item(item: WorkItem | int, *, user: User) -> WorkItem:
    """Gives a claimed, not yet started task back to its candidates."""
    with transaction.atomic():
        case, item = progress.lock_operator_item(item, user)
        if item.state != WorkItemState.CLAIMED or item.claimed_by_id != user.pk:
            raise Conflict(_moved_on(item, "unclaimed by you"))
        item.state, item.claimed_by = WorkItemState.OFFERED, None
        item.save(update_fields=["state", "claimed_by"])
        record_event(case, EventType.TASK_UNCLAIMED, item=item, user=user)
        case.save()
    return item


def reassign_work_item(item: WorkItem, *, by: User, to: User | None) -> WorkItem:
    """Hands an operator task to `to`, or gives a claimed one back to its candidates (`to` None):
    what a supervisor does when its holder has gone. A started task stays started, with its new
    holder. Invalid when `to` may not perform it; Conflict when it has ended, or a started task
    would be left with nobody to finish it.
    """
    with transaction.atomic():
        case = progress.lock_case(item.case_id)
        item = WorkItem.objects.select_related("claimed_by").get(pk=item.pk)
        item.case = case  # what performers_of and the API's answer read
        _check_open(case)
        check_operator_task(item)
        if item.state not in OPEN_WORK_ITEM_STATES:
            raise Conflict(_moved_on(item, "reassigned"))
        holder = item.claimed_by
        if to is None:
            if item.state == WorkItemState.OFFERED:
                raise Conflict(f"Nobody holds {item.label}: name who should do it.")
            if item.state == WorkItemState.RUNNING:
                raise Conflict(f"{item.label} has started: name who finishes it.")
            item.state, item.claimed_by = WorkItemState.OFFERED, None
        else:
            # The same rule as the list the supervisor chose from.
            if not to.is_active:
                raise Invalid(f"{to.get_username()} cannot sign in any more: choose someone who can.")  # fmt: skip
            if not performers_of(item).filter(pk=to.pk).exists():
                raise Invalid(f"{to.get_username()} may not do {item.label}: not among its candidates or in its team.")  # fmt: skip
            if holder is not None and holder.pk == to.pk:
                raise Conflict(f"{to.get_username()} holds {item.label} already.")
            if item.state == WorkItemState.OFFERED:
                item.state = WorkItemState.CLAIMED
            item.claimed_by = to
        item.save(update_fields=["state", "claimed_by"])
        record_event(
            case, EventType.TASK_REASSIGNED, item=item, user=by,
            detail={"from": holder.get_username() if holder else None,
                    "to": to.get_username() if to else None},
        )  # fmt: skip
        case.save()
    return item


def start_work_item(item: WorkItem | int, *, user: User) -> WorkItem:
    """Starts an operator task (claiming it if nobody has); the other tasks of a choice withdraw.

    Conflict naming the task and its performer while another operator's task is in the shared
    area (space constraint); the refusal is recorded as an interruption of this task."""
    with transaction.atomic():
        case, item = progress.lock_operator_item(item, user)
        if item.state == WorkItemState.CLAIMED and item.claimed_by_id != user.pk:
            raise Conflict(f"{item.label} is claimed by someone else.")
        if item.state not in (WorkItemState.OFFERED, WorkItemState.CLAIMED):
            raise Conflict(_moved_on(item, "started"))
        if case.status != CaseStatus.RUNNING:
            raise Conflict(f"Case {case.pk} is {case.status}: nothing can start now.")
        net = net_of(case)
        kept_out = progress.kept_out_by(case, net, item)
        if kept_out is not None:
            # Recorded and committed, then refused: the refusal is part of the case's history.
            refusal = progress.keep_out(case, item, *kept_out)
            case.save()
        else:
            _start_operator_task(case, net, item, user)
    if kept_out is not None:
        raise Conflict(refusal)
    return item


def _start_operator_task(case: Case, net: CaseNet, item: WorkItem, user: User) -> None:
    try:
        progress.start_task(case, net, item, user)
    except NotEnabled as refused:
        raise Conflict(str(refused)) from None
    item.claimed_by = user
    item.save(update_fields=["state", "started_at", "claimed_by"])
    progress.advance_after_start(case, net, item.task)
    case.save()


def complete_work_item(
    item: WorkItem | int, *, user: User, data: Mapping[str, Any] | None = None
) -> WorkItem:
    """Completes a running operator task with its form data (checked against the task's form).

    Raises Invalid naming each field the form refuses, Conflict when the task
    is not running (someone completed it already) or a func constraint still holds it.
    """
    # The cobot first: what this commits reaches the tablets once the step enabled by it has
    # gone to a worker (the sender would take the process's time from that send).
    hold = events.hold_publishing()
    try:
        with transaction.atomic():
            case, item = progress.lock_operator_item(item, user)
            if item.state != WorkItemState.RUNNING:
                raise Conflict(_moved_on(item, "completed"))
            if item.claimed_by_id != user.pk:
                raise Conflict(f"{item.label} is being done by someone else.")
            net = net_of(case)
            result = dict(data or {})
            if fields := form_problems(net.tasks[item.task].form, result):
                listed = "; ".join(f"{name}: {m}" for name, ms in fields.items() for m in ms)
                raise Invalid(f"The form is not filled in correctly: {listed}", fields)
            try:
                progress.complete_task(case, net, item, result, user)
            except NotEnabled as refused:
                raise Conflict(str(refused)) from None
            progress.advance(case, net)
            progress.hand_over(case, net)  # a step it enabled goes to a free cobot now
            case.save()
    finally:
        hold.release()
    return item


def confirm_left_area(item: WorkItem, *, by: User) -> bool:
    """Records that the operator of a cancelled task has left the shared area (said by that
    operator on the tablet, or by a supervisor): the cobots its presence paused or slowed resume.
    Whether anything was still held: a second confirmation changes nothing. Conflict unless the
    task was cancelled. The caller has checked that `by` may say so for this item."""
    with transaction.atomic():
        case = progress.lock_case(item.case_id)
        item = WorkItem.objects.get(pk=item.pk)
        if item.state != WorkItemState.CANCELLED:
            raise Conflict(f"{item.label} was not cancelled: the area is cleared when it ends.")
        if not progress.end_presence(case, item):
            return False
        record_event(case, EventType.AREA_LEFT, item=item, user=by)
        case.save()
    return True


def resolve_incident(
    incident: Incident,
    *,
    by: User,
    resolution: str,
    outputs: Mapping[str, Any] | None = None,
    again: bool = False,
) -> Incident:
    """Retry (the job is queued again; `again` runs a step that ran once more), skip (the task
    completes with `outputs`), or cancel the case. Conflict when it is resolved already.
    """
    if resolution not in Resolution.values:
        raise Invalid(f"resolution must be one of {', '.join(Resolution.values)}, not {resolution!r}.")  # fmt: skip
    with transaction.atomic():
        case = progress.lock_case(incident.case_id)
        incident = Incident.objects.select_for_update().get(pk=incident.pk)
        if incident.resolved_at is not None:
            raise Conflict(f"Incident {incident.pk} was resolved already ({incident.resolution}).")
        item = incident.work_item
        if resolution != Resolution.CANCEL:
            _check_open(case)
            if item is None or item.state not in OPEN_WORK_ITEM_STATES:
                raise Conflict("Only cancel resolves this incident: it has no open task to retry or skip.")  # fmt: skip
        net = net_of(case)
        if resolution == Resolution.CANCEL:
            if case.status in OPEN_CASE_STATUSES:
                progress.end_as_cancelled(case, by, {"incident": incident.pk})
        elif resolution == Resolution.RETRY:
            progress.retry_job(case, net, item, again)  # type: ignore[arg-type]
        else:
            progress.skip_task(case, net, item, dict(outputs or {}), by)  # type: ignore[arg-type]
        incident.resolution, incident.resolved_by = resolution, by
        incident.resolved_at = timezone.now()
        incident.save(update_fields=["resolution", "resolved_by", "resolved_at"])
        record_event(
            case, EventType.INCIDENT_RESOLVED, item=item, user=by,
            detail={"incident": incident.pk, "resolution": resolution},
        )  # fmt: skip
        case.save()
    return incident


def _check_open(case: Case) -> None:
    if case.status not in OPEN_CASE_STATUSES:
        raise Conflict(f"Case {case.pk} has ended ({case.status}).")


def _moved_on(item: WorkItem, wanted: str) -> str:
    return f"{item.label} cannot be {wanted}: it is {item.state} now."


def hand_back_work_items(user: User, organisation_id: int, by: User | None) -> int:
    """Gives every task `user` has claimed in the organisation and not started back to its
    candidates (an event each); returns how many. A started task stays theirs, as in
    reassign_work_item: its start has fired. Registered with hrc.organisations.hooks."""
    held = WorkItem.objects.filter(
        case__organisation_id=organisation_id, claimed_by=user,
        kind=WorkItemKind.OPERATOR, state=WorkItemState.CLAIMED,
    ).values_list("pk", "case_id")  # fmt: skip
    handed_back = 0
    for item_id, case_id in list(held):
        with transaction.atomic():
            case = progress.lock_case(case_id)
            item = WorkItem.objects.get(pk=item_id)
            if item.claimed_by_id != user.pk or item.state != WorkItemState.CLAIMED:
                continue  # moved on before the lock
            item.state, item.claimed_by = WorkItemState.OFFERED, None
            item.save(update_fields=["state", "claimed_by"])
            record_event(
                case, EventType.TASK_REASSIGNED, item=item, user=by,
                detail={"from": user.get_username(), "to": None, "why": "deactivated"},
            )  # fmt: skip
            case.save()
            handed_back += 1
    return handed_back
