"""Reads of cases, work items, jobs and incidents across the organisation wall.

Every function starts from the user's organisations, so an outsider gets
empty querysets (and the API 404s) whatever ids they try; only the reads of
what holds a cobot (for the lease, and for a cobot page that has checked its
user already) take a cobot as it is.
"""

from collections.abc import Iterable
from typing import Any

from django.contrib.auth.models import User
from django.db.models import Case as SqlCase
from django.db.models import (
    Count,
    Exists,
    IntegerField,
    OuterRef,
    Prefetch,
    Q,
    QuerySet,
    Subquery,
    Value,
    When,
)
from django.db.models.functions import Coalesce

from hrc.cases.choices import (
    OPEN_WORK_ITEM_STATES,
    JobState,
    TimerState,
    WorkItemKind,
    WorkItemState,
)
from hrc.cases.models import (
    Case,
    CaseEvent,
    CaseTimer,
    Incident,
    Interruption,
    Job,
    Message,
    WorkItem,
)
from hrc.cases.nets import net_of
from hrc.engine.petri import Marking
from hrc.organisations.models import Team
from hrc.organisations.selectors import AnyUser, organisations_of, writable_organisations

# The jobs a cobot has still to do or is doing: its queue.
QUEUE_STATES = (JobState.QUEUED, JobState.RUNNING)


def cases_visible_to(user: AnyUser) -> QuerySet[Case]:
    """The cases of the user's organisations, with their version and pattern."""
    return Case.objects.filter(organisation__in=organisations_of(user)).select_related(
        "version__pattern", "started_by"
    )


def with_open_work(cases: QuerySet[Case], user: AnyUser) -> QuerySet[Case]:
    """The cases with `open_work_items` and `open_incidents` (lists) prefetched."""
    open_items = work_items_visible_to(user).filter(state__in=OPEN_WORK_ITEM_STATES)
    open_incidents = Incident.objects.filter(resolved_at__isnull=True).select_related("work_item")
    return cases.prefetch_related(
        Prefetch("work_items", open_items.order_by("offered_at", "id"), "open_work_items"),
        Prefetch("incidents", open_incidents.order_by("opened_at", "id"), "open_incidents"),
    )


def events_of(case: Case, *, after: int | None = None) -> QuerySet[CaseEvent]:
    """The case's log in order; only the events after sequence number `after` when given."""
    events = CaseEvent.objects.filter(case=case).select_related("user").order_by("seq")
    return events if after is None else events.filter(seq__gt=after)


def work_items_of_organisations_of(user: AnyUser) -> QuerySet[WorkItem]:
    """The user's organisations' work items, bare: the wall, nothing read along."""
    return WorkItem.objects.filter(case__organisation__in=organisations_of(user))


def work_items_visible_to(user: AnyUser) -> QuerySet[WorkItem]:
    """Every work item, open or not, of the user's organisations' cases (read access)."""
    return (
        work_items_of_organisations_of(user)
        .select_related("case__version", "claimed_by", "completed_by", "cobot", "device", "job")
        .annotate(queue_position=_queue_position("job__"))
    )


def performable_by(user: AnyUser) -> Q:
    """Operator work items offered to `user`: as a candidate or as a member of the item's team.

    Subqueries, not joins, so the rows stay one per item without DISTINCT; the
    rule the work item services enforce (progress.lock_operator_item).
    """
    if not user.is_authenticated:
        return Q(pk__in=[])
    candidate = WorkItem.candidates.through.objects.filter(
        workitem_id=OuterRef("pk"), user_id=user.pk
    )
    in_team = Team.members.through.objects.filter(
        team_id=OuterRef("team_id"), membership__user_id=user.pk
    )
    return Q(kind=WorkItemKind.OPERATOR) & (Q(Exists(candidate)) | Q(Exists(in_team)))


def performers_of(item: WorkItem) -> QuerySet[User]:
    """The active members who may do an operator work item, by name: its candidates, and the
    members of its team (performable_by's rule, from the item's side)."""
    may = Q(
        pk__in=WorkItem.candidates.through.objects.filter(workitem_id=item.pk).values("user_id")
    )
    if item.team_id is not None:
        may |= Q(memberships__teams__id=item.team_id)
    organisation = item.case.organisation_id
    return (
        User.objects.filter(
            may,
            is_active=True,
            memberships__organisation_id=organisation,
            memberships__is_active=True,  # the same membership: not deactivated there
        )
        .distinct()
        .order_by("username")
    )


def task_list(user: AnyUser, kinds: Iterable[str] = (WorkItemKind.OPERATOR,)) -> QuerySet[WorkItem]:
    """Open work items for the user's task list, in the order they were offered; one query.

    Operator items: those the user may perform that nobody else holds (offered,
    or claimed or started by the user). Cobot items (step, device): every open
    one of the user's organisations, to follow read-only.
    """
    kinds = set(kinds)
    wanted = Q(pk__in=[])
    if WorkItemKind.OPERATOR in kinds:
        mine = Q(state=WorkItemState.OFFERED) | Q(claimed_by_id=user.pk)
        wanted |= performable_by(user) & mine
    cobot_kinds = kinds & {WorkItemKind.STEP, WorkItemKind.DEVICE}
    if cobot_kinds:
        wanted |= Q(kind__in=sorted(cobot_kinds))
    return (
        work_items_visible_to(user)
        .filter(wanted, state__in=OPEN_WORK_ITEM_STATES)
        .order_by("offered_at", "id")
    )


def jobs_visible_to(user: AnyUser) -> QuerySet[Job]:
    """Every job of the user's organisations' cases, with its `queue_position` annotated."""
    return (
        Job.objects.filter(case__organisation__in=organisations_of(user))
        .select_related("work_item", "cobot")
        .annotate(queue_position=_queue_position(""))
    )


def cobot_queues(user: AnyUser) -> QuerySet[Job]:
    """Queued and running jobs in queue order: per cobot, then per device, the running one, then
    first come first served."""
    running_first = SqlCase(When(state=JobState.RUNNING, then=Value(0)), default=Value(1))
    return (
        jobs_visible_to(user)
        .filter(state__in=QUEUE_STATES)
        .order_by("cobot_id", "device_id", running_first, "queued_at", "id")
    )


def _queue_position(prefix: str) -> SqlCase:
    """0 for the job on its cobot now, 1 for the next in line…; null once it has left the queue."""
    return SqlCase(
        When(**{f"{prefix}state": JobState.RUNNING}, then=Value(0)),
        When(**{f"{prefix}state": JobState.QUEUED}, then=_queued_ahead(prefix) + 1),
        default=None,
        output_field=IntegerField(),
    )


def _queued_ahead(prefix: str) -> Coalesce:
    """How many queued jobs of the same queue (cobot or device) came before the job at `prefix` (FCFS order)."""
    earlier = Q(queued_at__lt=OuterRef(f"{prefix}queued_at")) | Q(
        queued_at=OuterRef(f"{prefix}queued_at"), pk__lt=OuterRef(f"{prefix}pk")
    )
    ahead = (
        # The same queue: the job's cobot's, or its device's (a NULL matches neither).
        Job.objects.filter(
            earlier,
            Q(cobot_id=OuterRef(f"{prefix}cobot_id")) | Q(device_id=OuterRef(f"{prefix}device_id")),
            state=JobState.QUEUED,
        )
        .order_by()
        .values("cobot_id")
        .annotate(n=Count("pk"))
        .values("n")
    )
    return Coalesce(Subquery(ahead), Value(0))


# Cobots in use: a step running, or a func hold -------------------------------------------


def holding_work_items() -> QuerySet[WorkItem]:
    """Cobot work items that hold their cobot: the step has run (its job succeeded) but a func
    constraint holds the task until the task it supports completes. The cobot may hold the part
    meanwhile, so no other case may move it (jobs.py). An item whose completion opened an
    incident (its outputs did not map) is not held, but waits for a person: it holds nothing."""
    undecided = Incident.objects.filter(work_item=OuterRef("pk"), resolved_at__isnull=True)
    return WorkItem.objects.filter(
        state=WorkItemState.RUNNING, job__state=JobState.SUCCEEDED
    ).exclude(Exists(undecided))


def why_held(cobot_id: int, *, other_than: int | None = None) -> str:
    """'holding for: <supported task>, case N' when a func hold reserves the cobot (for a case
    other than `other_than`, given); "" when none does."""
    holding = holding_work_items().filter(cobot_id=cobot_id)
    if other_than is not None:
        holding = holding.exclude(case_id=other_than)
    item = holding.select_related("case__version").first()
    if item is None:
        return ""
    case = item.case
    net = net_of(case)
    tasks = net.holding_for(item.task, Marking(case.marking)) or net.holding_for(item.task)
    labels = " and ".join(net.labels[task] for task in tasks) or item.label
    return f"holding for: {labels}, case {case.pk}"


def cobot_in_use(cobot_id: int) -> str:
    """Why a case is using the cobot now, as a sentence; "" when none is.

    A step (or device call) running: "step N of <task>, case M is running". A
    func hold: "holding for: <supported task>, case M". Reads across organisations:
    the caller has checked the user may see the cobot.
    """
    running = (
        Job.objects.filter(cobot_id=cobot_id, state=JobState.RUNNING)
        .select_related("work_item")
        .first()
    )
    if running is not None:
        label, number = running.work_item.label, (running.command or {}).get("number")
        what = f"step {number} of {label}" if running.kind == WorkItemKind.STEP else label
        return f"{what}, case {running.case_id} is running"
    return why_held(cobot_id)


def incidents_visible_to(user: AnyUser, *, open_only: bool = True) -> QuerySet[Incident]:
    """Incidents of the user's organisations' cases, newest first; only unresolved by default."""
    incidents = Incident.objects.filter(case__organisation__in=organisations_of(user))
    if open_only:
        incidents = incidents.filter(resolved_at__isnull=True)
    return incidents.select_related("case", "work_item", "resolved_by").order_by(
        "-opened_at", "-id"
    )


# The supervisor pages (engineers and admins) ---------------------------------------------


def supervised_cases(user: AnyUser) -> QuerySet[Case]:
    """The cases of the organisations where the user is an engineer or admin, newest first,
    with `open_incident_count` annotated and `current_work_items` (open, in offer order)
    prefetched."""
    open_items = WorkItem.objects.filter(state__in=OPEN_WORK_ITEM_STATES).select_related(
        "claimed_by", "cobot"
    )
    return (
        Case.objects.filter(organisation__in=writable_organisations(user))
        .select_related("version__pattern", "started_by")
        .annotate(
            open_incident_count=Count("incidents", filter=Q(incidents__resolved_at__isnull=True))
        )
        .prefetch_related(
            Prefetch("work_items", open_items.order_by("offered_at", "id"), "current_work_items")
        )
        .order_by("-started_at", "-id")
    )


def supervised_incidents(user: AnyUser) -> QuerySet[Incident]:
    """Unresolved incidents of the cases of the organisations where the user is an engineer or
    admin, newest first, with their case's pattern."""
    return (
        Incident.objects.filter(
            case__organisation__in=writable_organisations(user), resolved_at__isnull=True
        )
        .select_related("case__version__pattern", "work_item", "resolved_by")
        .order_by("-opened_at", "-id")
    )


def incidents_of(case: Case) -> QuerySet[Incident]:
    """All the case's incidents, resolved or not, newest first."""
    return (
        Incident.objects.filter(case=case)
        .select_related("work_item", "resolved_by")
        .order_by("-opened_at", "-id")
    )


def interruptions_of(case: Case) -> QuerySet[Interruption]:
    """The case's interruptions in the order they began, with both tasks and the cobot."""
    return (
        Interruption.objects.filter(case=case)
        .select_related("work_item", "by_work_item", "cobot")
        .order_by("started_at", "id")
    )


def armed_timers_of(case: Case) -> QuerySet[CaseTimer]:
    """The timers the case waits for, the first due first."""
    return CaseTimer.objects.filter(case=case, state=TimerState.ARMED).order_by("due_at", "id")


def messages_of(case: Case) -> QuerySet[Message]:
    """The messages the case sent or took, in the order they were sent, with the other case."""
    return (
        Message.objects.filter(Q(sent_from_case=case) | Q(case=case))
        .select_related("case", "sent_from_case")
        .order_by("received_at", "id")
    )


def cobot_queue_lengths(cobot_ids: Iterable[int]) -> dict[int, int]:
    """How many jobs each cobot has queued or running, by cobot id (absent: none)."""
    counts = (
        Job.objects.filter(cobot_id__in=list(cobot_ids), state__in=QUEUE_STATES)
        .values("cobot_id")
        .annotate(n=Count("id"))
    )
    return {row["cobot_id"]: row["n"] for row in counts}


def device_queues(device_ids: Iterable[int]) -> dict[int, list[dict[str, Any]]]:
    """Each device's running call, then its queued ones first come first served, by device id."""
    running_first = SqlCase(When(state=JobState.RUNNING, then=Value(0)), default=Value(1))
    queues: dict[int, list[dict[str, Any]]] = {}
    rows = (
        Job.objects.filter(device_id__in=list(device_ids), state__in=QUEUE_STATES)
        .order_by("device_id", running_first, "queued_at", "id")
        .values_list("device_id", "case_id", "work_item__label", "work_item__task", "state",
                     "waiting_for")
    )  # fmt: skip
    for device_id, case_id, label, task, state, waiting_for in rows:
        queues.setdefault(device_id, []).append(
            {"case": case_id, "label": label or task, "state": state, "waiting_for": waiting_for}
        )
    return queues
