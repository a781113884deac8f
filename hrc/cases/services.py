"""Every write to a case: start, advance, work items, incidents, cancel, suspend, resume.

Each public function takes the case row lock (select_for_update) for its
whole transaction, so two tablets, a worker and a message can never change
one case at once; the engine's CaseNet decides what the marking allows.
Lock order, everywhere: cobot row, then case row, then job row, then
interruption row. Broadcast and dispatch happen after commit (dispatch.py).

Errors: Refusal subclasses, each with the HTTP status the API answers:
Conflict (409: the case or work item has moved on), NotAllowed (403: not
this user's task), Invalid (400: the input is wrong).
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from typing import Any

import jsonschema
from django.contrib.auth.models import User
from django.db import transaction
from django.db.models import Exists, OuterRef, Q, Subquery
from django.utils import timezone

from hrc.cases import dispatch
from hrc.cases.choices import (
    OPEN_CASE_STATUSES,
    OPEN_WORK_ITEM_STATES,
    CaseStatus,
    EventType,
    IncidentKind,
    JobState,
    Resolution,
    WorkItemKind,
    WorkItemState,
)
from hrc.cases.mapping import resolve_actor_mapping
from hrc.cases.models import Case, CaseEvent, Incident, Interruption, Job, WorkItem
from hrc.cases.nets import case_net
from hrc.engine.petri import Marking
from hrc.engine.runtime import CaseNet, NotEnabled, RuntimeFault, apply_outputs, resolve
from hrc.engine.startdata import check_start_data
from hrc.engine.taskconfig import POSE_LENGTH, TaskConfig
from hrc.errors import Conflict, Invalid, NotAllowed, NotFound
from hrc.live import broadcast as live
from hrc.patterns.models import PatternVersion

# A start form's "count": enough for a shift's batch, not a load test by accident.
MAX_CASES_AT_ONCE = 50
REFERENCE_LENGTH = Case._meta.get_field("reference").max_length or 100
# advance() repeats settle → messages → held completions until nothing changes;
# each round consumes a token or a message, so a sound net stops long before this.
MAX_ROUNDS = 10_000


# Starting and ending cases ----------------------------------------------------------


def start_case(
    version: PatternVersion,
    *,
    started_by: User | None,
    actor_mapping: Mapping[str, Any] | None = None,
    data: Mapping[str, Any] | None = None,
    reference: str = "",
) -> Case:
    """Starts a case of a published version; the mapping overrides the version's defaults per actor,
    `data` the pattern's initial data per key.

    Raises Invalid when the version is retired, an actor is left unmapped or
    mapped to someone outside the organisation, or a data key is not the
    pattern's or not of its type.
    """
    return start_cases(
        version,
        started_by=started_by,
        actor_mapping=actor_mapping,
        data=data,
        reference=reference,
        count=1,
    )[0]


def start_cases(
    version: PatternVersion,
    *,
    started_by: User | None,
    actor_mapping: Mapping[str, Any] | None = None,
    data: Mapping[str, Any] | None = None,
    reference: str = "",
    count: int = 1,
) -> list[Case]:
    """Starts `count` cases alike, all or none (start_case's checks, once)."""
    if version.retired_at is not None:
        raise Invalid.at("version", f"{version} is retired: it starts no new cases.")
    if not 1 <= count <= MAX_CASES_AT_ONCE:
        raise Invalid.at("count", f"Start between 1 and {MAX_CASES_AT_ONCE} cases at once.")
    if len(reference) > REFERENCE_LENGTH:
        raise Invalid.at(
            "reference", f"The reference is longer than {REFERENCE_LENGTH} characters."
        )
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
                organisation=organisation,
                version=version,
                marking=dict(net.initial),
                data={
                    **net.initial_data(),
                    **(data or {}),
                },  # the pattern's `data`, then the case's
                actor_mapping=mapping,
                started_by=started_by,
                reference=reference,
            )
            case = lock_case(case.pk)
            record_event(case, EventType.CASE_STARTED, user=started_by, after=net.initial)
            advance(case, net)
            case.save()
            cases.append(case)
    return cases


def set_default_actor_mapping(
    version: PatternVersion, mapping: Mapping[str, Any]
) -> PatternVersion:
    """Sets who performs each actor in the version's cases unless a case says otherwise.

    Raises Invalid as start_case does. Only this field of a version ever changes.
    """
    resolved = resolve_actor_mapping(
        case_net(version).pattern, version.pattern.organisation, mapping
    )
    PatternVersion.objects.filter(pk=version.pk).update(default_actor_mapping=resolved)
    version.default_actor_mapping = resolved
    return version


def cancel_case(case: Case, *, by: User | None, reason: str = "") -> Case:
    """Cancels an open case: open work is withdrawn and queued jobs are cancelled.

    A step already running on a cobot finishes (the cobot is not stopped by
    this); its result is then ignored. Raises Conflict when the case has ended.
    """
    with transaction.atomic():
        case = lock_case(case.pk)
        _check_open(case)
        _end(case, CaseStatus.CANCELLED, EventType.CASE_CANCELLED, by, {"reason": reason})
        case.save()
    return case


def suspend_case(case: Case, *, by: User | None) -> Case:
    """Stops offering and dispatching new work; tasks already running may finish."""
    with transaction.atomic():
        case = lock_case(case.pk)
        if case.status != CaseStatus.RUNNING:
            raise Conflict(f"Case {case.pk} is {case.status}, not running: it cannot be suspended.")
        case.status = CaseStatus.SUSPENDED
        record_event(case, EventType.CASE_SUSPENDED, user=by)
        case.save()
    return case


def resume_case(case: Case, *, by: User | None) -> Case:
    with transaction.atomic():
        case = lock_case(case.pk)
        if case.status != CaseStatus.SUSPENDED:
            raise Conflict(f"Case {case.pk} is {case.status}, not suspended.")
        case.status = CaseStatus.RUNNING
        record_event(case, EventType.CASE_RESUMED, user=by)
        advance(case, case_net(case.version))
        _dispatch_queues(case)
        case.save()
    return case


# Operator work items ---------------------------------------------------------------
#
# Each takes the work item or its id (the API's, unread) and reads it again under its
# case's lock; NotFound when it is not one of the user's organisations'.


def claim_work_item(item: WorkItem | int, *, user: User) -> WorkItem:
    """Takes an offered operator task for `user`; Conflict when someone else has it."""
    with transaction.atomic():
        case, item = _locked_item(item, user)
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
        case, item = _locked_item(item, user)
        if item.state != WorkItemState.CLAIMED or item.claimed_by_id != user.pk:
            raise Conflict(_moved_on(item, "unclaimed by you"))
        item.state, item.claimed_by = WorkItemState.OFFERED, None
        item.save(update_fields=["state", "claimed_by"])
        record_event(case, EventType.TASK_UNCLAIMED, item=item, user=user)
        case.save()
    return item


def reassign_work_item(item: WorkItem, *, by: User, to: User | None) -> WorkItem:
    """Hands an operator task to `to`, or gives a claimed one back to its candidates (`to` None):
    what a supervisor does when the operator who holds it has gone. A started task stays
    started, with its new holder, who completes it. The API lets engineers and admins only.

    Invalid when `to` may not perform it (not a candidate, not in its team, not an active member);
    Conflict when it has ended, or a started task would be left with nobody to finish it.
    """
    from hrc.cases.selectors import performers_of

    with transaction.atomic():
        case = lock_case(item.case_id)
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
    """Starts an operator task (claiming it if nobody has); the other tasks of a choice withdraw."""
    with transaction.atomic():
        case, item = _locked_item(item, user)
        if item.state == WorkItemState.CLAIMED and item.claimed_by_id != user.pk:
            raise Conflict(f"{item.label} is claimed by someone else.")
        if item.state not in (WorkItemState.OFFERED, WorkItemState.CLAIMED):
            raise Conflict(_moved_on(item, "started"))
        if case.status != CaseStatus.RUNNING:
            raise Conflict(f"Case {case.pk} is {case.status}: nothing can start now.")
        net = case_net(case.version)
        try:
            _start(case, net, item, user)
        except NotEnabled as refused:
            raise Conflict(str(refused)) from None
        item.claimed_by = user
        item.save(update_fields=["state", "started_at", "claimed_by"])
        advance(case, net)
        case.save()
    return item


def complete_work_item(
    item: WorkItem | int, *, user: User, data: Mapping[str, Any] | None = None
) -> WorkItem:
    """Completes a running operator task with its form data (checked against the task's form).

    Raises Invalid naming each field the form refuses, Conflict when the task
    is not running (someone completed it already) or a func constraint still holds it.
    """
    with transaction.atomic():
        case, item = _locked_item(item, user)
        if item.state != WorkItemState.RUNNING:
            raise Conflict(_moved_on(item, "completed"))
        if item.claimed_by_id != user.pk:
            raise Conflict(f"{item.label} is being done by someone else.")
        net = case_net(case.version)
        result = dict(data or {})
        _check_form(net.tasks[item.task], result)
        try:
            _complete(case, net, item, result, user)
        except NotEnabled as refused:
            raise Conflict(str(refused)) from None
        advance(case, net)
        case.save()
    return item


def _check_form(config: TaskConfig, data: Mapping[str, Any]) -> None:
    """Invalid, naming each field the form refuses: a required answer that is missing too.
    The data is stored as given: nothing is filled in for a field the operator left out."""
    if config.form is None:
        return
    validator = jsonschema.Draft202012Validator(config.form)
    fields: dict[str, list[str]] = {}
    for problem in sorted(validator.iter_errors(data), key=lambda e: list(e.absolute_path)):
        for name, message in _form_problems(problem):
            fields.setdefault(name, []).append(message)
    if fields:
        raise Invalid(
            "The form is not filled in correctly: "
            + "; ".join(
                f"{name}: {message}" for name, messages in fields.items() for message in messages
            ),
            fields,
        )


def _form_problems(problem: jsonschema.ValidationError) -> list[tuple[str, str]]:
    """(field, message) for one refusal; a missing required answer is named by its field, not
    reported against the form as a whole."""
    path = list(problem.absolute_path)
    if problem.validator == "required" and isinstance(problem.instance, Mapping):
        return [
            (_field([*path, name]), "an answer is required")
            for name in problem.validator_value
            if name not in problem.instance
        ]
    return [(_field(path), problem.message)]


def _field(path: Iterable[Any]) -> str:
    return ".".join(str(part) for part in path) or "the form"


# Incidents ------------------------------------------------------------------------


def open_incident(
    case: Case,
    kind: IncidentKind,
    message: str,
    *,
    item: WorkItem | None = None,
    cobot_state: Mapping[str, Any] | None = None,
) -> Incident:
    """Records an incident. Call while holding the case row lock."""
    incident = Incident.objects.create(
        case=case, work_item=item, kind=kind, message=message,
        cobot_state=dict(cobot_state) if cobot_state else None,
    )  # fmt: skip
    record_event(
        case,
        EventType.INCIDENT_OPENED,
        item=item,
        detail={"incident": incident.pk, "kind": kind, "message": message},
    )
    return incident


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
        raise Invalid(
            f"resolution must be one of {', '.join(Resolution.values)}, not {resolution!r}."
        )
    with transaction.atomic():
        case = lock_case(incident.case_id)
        incident = Incident.objects.select_for_update().get(pk=incident.pk)
        if incident.resolved_at is not None:
            raise Conflict(f"Incident {incident.pk} was resolved already ({incident.resolution}).")
        item = incident.work_item
        if resolution != Resolution.CANCEL:
            _check_open(case)
            if item is None or item.state not in OPEN_WORK_ITEM_STATES:
                raise Conflict(
                    "Only cancel resolves this incident: it has no open task to retry or skip."
                )
        net = case_net(case.version)
        if resolution == Resolution.CANCEL:
            if case.status in OPEN_CASE_STATUSES:
                _end(
                    case,
                    CaseStatus.CANCELLED,
                    EventType.CASE_CANCELLED,
                    by,
                    {"incident": incident.pk},
                )
        elif resolution == Resolution.RETRY:
            _retry(case, net, item, again)  # type: ignore[arg-type]
        else:
            _skip(case, net, item, dict(outputs or {}), by)  # type: ignore[arg-type]
        incident.resolution, incident.resolved_by = resolution, by
        incident.resolved_at = timezone.now()
        incident.save(update_fields=["resolution", "resolved_by", "resolved_at"])
        record_event(
            case,
            EventType.INCIDENT_RESOLVED,
            item=item,
            user=by,
            detail={"incident": incident.pk, "resolution": resolution},
        )
        case.save()
    return incident


def _retry(case: Case, net: CaseNet, item: WorkItem, again: bool) -> None:
    job = Job.objects.select_for_update().filter(work_item=item).first()
    if job is None:
        raise Conflict(f"{item.label} is an operator task: there is nothing to retry.")
    if job.state == JobState.RUNNING:
        raise Conflict(f"{item.label} is running again already.")
    command = (
        _command(net, item.task, case.data)
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
    if again:
        job.attempt += 1
    job.save()
    dispatch.send_on_commit("run_job", job.pk)


def _skip(case: Case, net: CaseNet, item: WorkItem, outputs: dict[str, Any], by: User) -> None:
    Job.objects.filter(work_item=item).exclude(state=JobState.SUCCEEDED).update(
        state=JobState.CANCELLED, ended_at=timezone.now()
    )
    if item.state != WorkItemState.RUNNING:
        try:
            _start(case, net, item, by)
        except NotEnabled as refused:
            raise Conflict(f"{item.label} cannot be skipped now: {refused}") from None
    try:
        _complete(case, net, item, outputs, by)
    except NotEnabled as refused:
        raise Conflict(f"{item.label} cannot be skipped now: {refused}") from None
    advance(case, net)


# The engine's firing rule applied to the rows ----------------------------------------


def advance(case: Case, net: CaseNet) -> None:
    """Fires what fires by itself and brings the work items in line with the marking.

    Silent transitions fire, buffered messages are taken, cobot tasks whose
    step is done complete once their func constraints allow; then the case
    completes, or tasks that became startable are offered and those that
    stopped being startable are withdrawn. Call while holding the case row
    lock; the caller saves the case.
    """
    if case.status not in OPEN_CASE_STATUSES:
        return
    from hrc.cases.messages import take_buffered_message  # messages build on these services

    try:
        for _ in range(MAX_ROUNDS):
            fired = _settle(case, net)
            taken = take_buffered_message(case, net)
            held = _complete_held_steps(case, net)
            if not (fired or taken or held):
                break
    except RuntimeFault as fault:
        _fail(case, str(fault))
        return
    marking = Marking(case.marking)
    if net.is_final(marking):
        _end(case, CaseStatus.COMPLETED, EventType.CASE_COMPLETED, None, {})
        return
    if case.status == CaseStatus.RUNNING:
        _offer_and_withdraw(case, net, marking)


def _settle(case: Case, net: CaseNet) -> bool:
    before = Marking(case.marking)
    after, fired = net.settle(before, case.data)
    marking = before
    for transition in fired:
        after_one = net.transition(transition).fire(marking)
        record_event(
            case, EventType.TRANSITION_FIRED, task=transition, before=marking, after=after_one
        )
        marking = after_one
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
    open_items = {
        item.task: item
        for item in WorkItem.objects.filter(case=case, state__in=OPEN_WORK_ITEM_STATES)
    }
    for task, item in open_items.items():
        if item.state != WorkItemState.RUNNING and task not in startable:
            _withdraw(case, item, "another task took its turn")
    for task in net.startable(marking):
        if task not in open_items:
            _offer(case, net, task)
    if not startable and not open_items and not net.waiting_messages(marking):
        _fail(
            case,
            f"The case cannot go on: nothing can start in marking {dict(marking)} "
            "(a guard that holds for no branch?).",
        )


def _offer(case: Case, net: CaseNet, task: str) -> WorkItem:
    config = net.tasks[task]
    actor = net.performers[task]
    binding = case.actor_mapping[actor]
    item = WorkItem.objects.create(
        case=case, task=task, label=net.labels[task], actor=actor,
        kind=config.kind, instructions=config.instructions,
        team_id=binding.get("team"), cobot_id=binding.get("cobot"),
    )  # fmt: skip
    if config.kind == "operator":
        # A new item has no candidates yet: insert them in one statement.
        Candidate = WorkItem.candidates.through
        Candidate.objects.bulk_create(
            Candidate(workitem_id=item.pk, user_id=user_id) for user_id in binding.get("users", ())
        )
    else:
        _queue_job(case, net, item, config)
    record_event(case, EventType.TASK_OFFERED, item=item)
    return item


def _queue_job(case: Case, net: CaseNet, item: WorkItem, config: TaskConfig) -> None:
    assert item.cobot_id is not None  # a cobot task's actor maps to a cobot (mapping.py)
    now = timezone.now()
    job = Job(
        work_item=item, case=case, cobot_id=item.cobot_id, kind=config.kind,
        timeout=config.timeout, retries_left=config.retries, next_try_at=now, command={},
    )  # fmt: skip
    try:
        job.command = _command(net, item.task, case.data)
    except RuntimeFault as fault:
        job.state, job.last_error = JobState.FAILED, str(fault)
        job.save()
        open_incident(case, IncidentKind.CASE_FAULT, str(fault), item=item)
        return
    job.save()
    dispatch.send_on_commit("run_job", job.pk)


def _command(net: CaseNet, task: str, data: Mapping[str, Any]) -> dict[str, Any]:
    """The job's command with its expressions evaluated over the case data now."""
    config = net.tasks[task]
    if config.device is not None:
        device = config.device
        args = [resolve(task, device.args[name], data) for name in device.argument_names]
        return {"method": device.method, "args": args, "outputs": list(device.output_names)}
    assert config.step is not None
    step = config.step
    poses = resolve(task, step.poses, data)
    flat = [float(v) for pose in poses for v in pose] if poses else []
    if len(flat) > 2 * POSE_LENGTH or len(flat) % POSE_LENGTH:
        raise RuntimeFault(
            f"{task}: the poses resolved to {poses!r}, not one or two 6-value poses."
        )
    return {
        "program": step.program,
        "number": _whole(task, "number", resolve(task, step.number, data)),
        "workspace": _whole(task, "workspace", resolve(task, step.workspace, data)),
        "poses": flat + [0.0] * (2 * POSE_LENGTH - len(flat)),
    }


def _whole(task: str, what: str, value: Any) -> int:
    if isinstance(value, bool) or not isinstance(value, int | float) or int(value) != value:
        raise RuntimeFault(f"{task}: the step {what} resolved to {value!r}, not a whole number.")
    return int(value)


def _withdraw(case: Case, item: WorkItem, why: str) -> None:
    if item.state == WorkItemState.RUNNING and item.kind != WorkItemKind.OPERATOR:
        held = Job.objects.filter(work_item=item, state=JobState.SUCCEEDED).first()
        if held is not None:  # the case ends while its func constraint holds the cobot
            _end_hold(held)
    item.state, item.ended_at = WorkItemState.WITHDRAWN, timezone.now()
    item.save(update_fields=["state", "ended_at"])
    Job.objects.filter(work_item=item, state__in=[JobState.QUEUED, JobState.FAILED]).update(
        state=JobState.CANCELLED, ended_at=item.ended_at
    )
    Incident.objects.filter(work_item=item, resolved_at__isnull=True).update(
        resolved_at=item.ended_at, resolution=Resolution.CANCEL
    )
    record_event(case, EventType.TASK_WITHDRAWN, item=item, detail={"why": why})


def _start(case: Case, net: CaseNet, item: WorkItem, user: User | None) -> None:
    """Fires the task's start; interrupts the cobots it shares a space with. Raises NotEnabled."""
    before = Marking(case.marking)
    after = net.start(before, item.task)
    case.marking = dict(after)
    item.state, item.started_at = WorkItemState.RUNNING, timezone.now()
    record_event(case, EventType.TASK_STARTED, item=item, user=user, before=before, after=after)
    if item.kind == WorkItemKind.OPERATOR:
        _interrupt_shared_space(case, net, item)


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
        _complete(case, net, item, result, None)
    except Invalid as fault:
        open_incident(
            case, IncidentKind.CASE_FAULT,
            f"{item.label} ran, but its outputs cannot go into the case data: {fault}", item=item,
        )  # fmt: skip
        return False
    return True


def start_cobot_task(case: Case, net: CaseNet, item: WorkItem) -> None:
    """Starts a cobot task as its cobot takes the job (jobs.lease_next_job).

    Call while holding the case row lock, with the start enabled; the caller saves the case.
    """
    _start(case, net, item, None)
    item.save(update_fields=["state", "started_at"])
    advance(case, net)


def _complete(
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
    except RuntimeFault as fault:
        raise Invalid(str(fault)) from None
    case.marking = dict(after)
    item.state, item.ended_at = WorkItemState.COMPLETED, timezone.now()
    item.result, item.completed_by = dict(result), user
    item.save(update_fields=["state", "ended_at", "result", "completed_by", "started_at"])
    record_event(case, EventType.TASK_COMPLETED, item=item, user=user, before=before, after=after)
    if item.task in net.space_tasks:  # only a space constraint's tasks are ever interrupted
        _end_interruptions(case, Q(work_item=item) | Q(operator_work_item=item))


# Space constraints: interruptions ------------------------------------------------------


def _interrupt_shared_space(case: Case, net: CaseNet, operator_item: WorkItem) -> None:
    for pair in net.space_pairs:
        if pair.operator_task != operator_item.task:
            continue
        cobot_item = WorkItem.objects.filter(
            case=case, task=pair.cobot_task, state=WorkItemState.RUNNING
        ).first()
        if cobot_item is None or cobot_item.cobot_id is None:
            continue  # not running: the cobot's job waits for the operator instead (jobs.py)
        interruption = Interruption.objects.create(
            case=case, work_item=cobot_item, operator_work_item=operator_item,
            cobot_id=cobot_item.cobot_id, mode=pair.mode,
        )  # fmt: skip
        record_event(case, EventType.TASK_INTERRUPTED, item=cobot_item,
                detail={"interruption": interruption.pk, "by": operator_item.task, "mode": pair.mode})  # fmt: skip
        dispatch.send_on_commit("interrupt_cobot", interruption.pk)


def _end_interruptions(case: Case, which: Q) -> None:
    for interruption in Interruption.objects.filter(which, case=case, ended_at__isnull=True):
        interruption.ended_at = timezone.now()
        interruption.save(update_fields=["ended_at"])
        seconds = (interruption.ended_at - interruption.started_at).total_seconds()
        record_event(case, EventType.TASK_RESUMED, item=interruption.work_item,
                detail={"interruption": interruption.pk, "seconds": round(seconds, 3)})  # fmt: skip
        dispatch.send_on_commit("resume_cobot", interruption.pk)


def _end_hold(job: Job) -> None:
    """The cobot a func hold reserved for this case is free once this transaction commits: its
    next job goes now, not at the next sweep. Held items end only by completing (advance's
    held completions, which a skip or a message reaches too) or by withdrawal (the case ends)."""
    ring_for_next_job_on_commit(job.pk, job.cobot_id)


def ring_for_next_job_on_commit(job_id: int, cobot_id: int) -> None:
    """Rings the doorbell of `job_id`'s cobot once this transaction has committed, if a job is
    queued for the cobot then: most often none is, and a doorbell would cost a task and a
    transaction to find nothing. Asked after the commit, so none is missed: a job queued
    meanwhile rang its own doorbell, which found the cobot busy, after it had committed."""

    def queued() -> bool:
        return Job.objects.filter(cobot_id=cobot_id, state=JobState.QUEUED).exists()

    dispatch.send_on_commit_if(queued, "run_job", job_id)


def _dispatch_queues(case: Case) -> None:
    """Rings the doorbell of each cobot the case has queued work for."""
    for job_id in Job.objects.filter(case=case, state=JobState.QUEUED).values_list("pk", flat=True):
        dispatch.send_on_commit("run_job", job_id)


# Case endings, locks, the event log ---------------------------------------------------


def _end(case: Case, status: str, event: str, by: User | None, detail: dict[str, Any]) -> None:
    for item in WorkItem.objects.filter(case=case, state__in=OPEN_WORK_ITEM_STATES):
        _withdraw(case, item, f"the case is {status}")
    _end_interruptions(case, Q())
    case.status, case.ended_at = status, timezone.now()
    record_event(case, event, user=by, detail=detail)


def _fail(case: Case, message: str) -> None:
    open_incident(case, IncidentKind.CASE_FAULT, message)
    _end(case, CaseStatus.FAILED, EventType.CASE_FAILED, None, {"message": message})


def lock_case(case_id: int) -> Case:
    """The case, its row locked until the transaction ends (its version read along, not locked)."""
    return (
        Case.objects.select_for_update(of=("self",), no_key=True)
        .select_related("version")
        .get(pk=case_id)
    )


def _locked_item(item: WorkItem | int, user: User) -> tuple[Case, WorkItem]:
    """The case (locked) and a fresh copy of an operator work item the user may perform,
    the case and the user it is claimed by attached.

    The case is found through the item and the user's memberships in the statement
    that locks it: the organisations' wall costs the API's request no read of its own.
    """
    from hrc.cases.selectors import performable_by

    item_id = item.pk if isinstance(item, WorkItem) else item
    case = (
        Case.objects.select_for_update(of=("self",), no_key=True)
        .select_related("version")
        .filter(
            pk=Subquery(WorkItem.objects.filter(pk=item_id).values("case_id")),
            organisation__memberships__user_id=user.pk,
            organisation__memberships__is_active=True,  # deactivated there: not theirs to do
        )
        .first()
    )
    if case is None:
        raise NotFound(f"There is no work item {item_id} in your organisations.")
    offered = WorkItem.objects.filter(
        performable_by(user),
        pk=OuterRef("pk"),
        case__organisation__memberships__user_id=user.pk,
        case__organisation__memberships__is_active=True,
    )  # a candidate (or in the item's team) and still a member; read with the item in one query
    item = WorkItem.objects.annotate(performable=Exists(offered)).get(pk=item_id)
    check_operator_task(item)
    if not item.performable:
        raise NotAllowed(f"{item.label} is not offered to you.")
    # What the caller hands back (the API's answer) reads these; they are in hand.
    item.case = case
    if item.claimed_by_id == user.pk:
        item.claimed_by = user
    return case, item


def check_operator_task(item: WorkItem) -> None:
    """Conflict unless the work item is an operator's (a cobot's is the workers' to drive)."""
    if item.kind != WorkItemKind.OPERATOR:
        raise Conflict(f"{item.label} is done by a cobot, not by an operator.")


def _check_open(case: Case) -> None:
    if case.status not in OPEN_CASE_STATUSES:
        raise Conflict(f"Case {case.pk} has ended ({case.status}).")


def _moved_on(item: WorkItem, wanted: str) -> str:
    return f"{item.label} cannot be {wanted}: it is {item.state} now."


def record_event(
    case: Case,
    event: str,
    *,
    item: WorkItem | None = None,
    task: str = "",
    user: User | None = None,
    before: Marking | None = None,
    after: Marking | None = None,
    detail: Mapping[str, Any] | None = None,
) -> CaseEvent:
    """Appends an event; the case's counter gives its number, so its cost never grows with the log.

    Call while holding the case row lock; the caller saves the case (its last_seq).
    """
    case.last_seq += 1
    live.case_event_on_commit(case, event, item, user, detail)  # the tablets, after commit
    marking = dict(case.marking)
    return CaseEvent.objects.create(
        case=case, seq=case.last_seq, at=timezone.now(), type=event,
        task=item.task if item else task, actor=item.actor if item else "",
        work_item=item, user=user if user is not None and user.is_authenticated else None,
        marking_before=dict(before) if before is not None else marking,
        marking_after=dict(after) if after is not None else marking,
        detail=dict(detail or {}),
    )  # fmt: skip


def hand_back_work_items(user: User, organisation_id: int, by: User | None) -> int:
    """Gives every task `user` has claimed in the organisation and not started back to its
    candidates, each with an event in its case's log; returns how many went back.

    A started task stays with them, as reassign_work_item keeps it: its start has fired
    in the case's net, so it cannot be offered afresh; the case page names it and a
    supervisor hands it to whoever finishes it. Registered with hrc.organisations.hooks
    for deactivation.
    """
    held = WorkItem.objects.filter(
        case__organisation_id=organisation_id,
        claimed_by=user,
        kind=WorkItemKind.OPERATOR,
        state=WorkItemState.CLAIMED,
    ).values_list("pk", "case_id")
    handed_back = 0
    for item_id, case_id in list(held):
        with transaction.atomic():
            case = lock_case(case_id)
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
