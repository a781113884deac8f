"""Reads for analytics: the organisation wall, then plain rows for hrc.analytics' pure modules.

Every lookup starts from the user's organisations (an outsider finds nothing,
whatever the id); the role check (engineers and admins only) is the views'.
Rows are read with values_list, only the columns the figures need, so a
version with thousands of cases costs a few queries, not a query per case.
"""

from __future__ import annotations

import datetime as dt
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

from django.contrib.auth.models import User
from django.db.models import Count, Max, OuterRef, Q, QuerySet, Subquery
from django.db.models.functions import Coalesce

from hrc.analytics import xes
from hrc.analytics.gantt import ActorRow, ConstraintRow, Gantt, build_gantt
from hrc.analytics.metrics import (
    COMPLETED,
    CaseRow,
    InterruptionRow,
    ItemRow,
    JobRow,
    VersionFigures,
    item_work_seconds,
    version_figures,
)
from hrc.cases.choices import CaseStatus, EventType, JobState
from hrc.cases.models import Case, CaseEvent, Interruption, Job, WorkItem
from hrc.cases.selectors import cases_visible_to
from hrc.cobots.models import Cobot
from hrc.engine import FormatError
from hrc.engine.document import read_pattern
from hrc.engine.model import Pattern
from hrc.organisations.models import Team
from hrc.organisations.selectors import AnyUser, writable_organisations
from hrc.patterns.models import PatternModel, PatternVersion
from hrc.patterns.prediction import Measured
from hrc.patterns.selectors import versions_visible_to

# A server-side cursor hands rows over in batches of this many.
STREAM_BATCH = 2000


# The wall -----------------------------------------------------------------------------------


def version_visible_to(user: AnyUser, pk: int) -> PatternVersion | None:
    """The published version if it belongs to one of the user's organisations, else None."""
    return versions_visible_to(user).filter(pk=pk).first()


def case_visible_to(user: AnyUser, pk: int) -> Case | None:
    """The case if it belongs to one of the user's organisations, else None."""
    return cases_visible_to(user).filter(pk=pk).first()


def analysed_versions(user: AnyUser) -> QuerySet[PatternVersion]:
    """The versions of the organisations where the user is an engineer or admin, with
    `case_count` and `last_started` annotated; those with cases first, newest first."""
    return (
        PatternVersion.objects.filter(pattern__organisation__in=writable_organisations(user))
        .select_related("pattern")
        .annotate(case_count=Count("cases"), last_started=Max("cases__started_at"))
        .order_by("-case_count", "pattern__name", "-number")
    )


# A version's figures ------------------------------------------------------------------------


def cases_of(
    version: PatternVersion, *, since: dt.datetime | None = None, until: dt.datetime | None = None
) -> QuerySet[Case]:
    """The version's cases that started in [since, until)."""
    window = Q()
    if since is not None:
        window &= Q(started_at__gte=since)
    if until is not None:
        window &= Q(started_at__lt=until)
    return Case.objects.filter(window, version=version)


def version_analytics(
    version: PatternVersion,
    *,
    now: dt.datetime,
    since: dt.datetime | None = None,
    until: dt.datetime | None = None,
) -> VersionFigures:
    cases = cases_of(version, since=since, until=until)
    return version_figures(
        case_rows(cases),
        item_rows(cases),
        job_rows(cases),
        interruption_rows(cases),
        now=now,
        task_order=task_order(version),
    )


def task_order(version: PatternVersion) -> list[str]:
    """The version's tasks (transitions with a performer) in document order."""
    pattern = _pattern(version)
    return [] if pattern is None else [t.id for _, t in pattern.transitions() if t.is_task]


def _pattern(version: PatternVersion) -> Pattern | None:
    try:
        return read_pattern(version.document)
    except FormatError:  # published documents are read before publishing; never expected
        return None


def case_rows(cases: QuerySet[Case]) -> list[CaseRow]:
    fields = ("pk", "status", "started_at", "ended_at")
    return [CaseRow(*row) for row in cases.order_by("pk").values_list(*fields)]


def item_rows(cases: QuerySet[Case]) -> list[ItemRow]:
    """The cases' work items; a cobot task counts as started when its cobot accepted the step
    that completed it, so time it spent stuck, queued again or retried is wait, not work."""
    fields = (
        "pk", "case_id", "task", "label", "actor", "kind", "state",
        "offered_at", "worked_from", "ended_at",
        "completed_by__username", "claimed_by__username", "cobot__name",
    )  # fmt: skip
    accepted = Job.objects.filter(work_item=OuterRef("pk"), state=JobState.SUCCEEDED)
    rows = (
        WorkItem.objects.filter(case__in=cases)
        .annotate(
            worked_from=Coalesce(
                Subquery(accepted.order_by("-ended_at").values("accepted_at")[:1]), "started_at"
            )
        )
        .order_by("offered_at", "pk")
    )
    return [_item_row(*row) for row in rows.values_list(*fields)]


def _item_row(
    pk: int, case_id: int, task: str, label: str, actor: str, kind: str, state: str,
    offered_at: dt.datetime, started_at: dt.datetime | None, ended_at: dt.datetime | None,
    completed_by: str | None, claimed_by: str | None, cobot: str | None,
) -> ItemRow:  # fmt: skip
    resource = completed_by or claimed_by or cobot or ""  # who did it, or has it, or its cobot
    return ItemRow(
        pk, case_id, task, label, actor, kind, state, offered_at, started_at, ended_at, resource
    )


def job_rows(cases: QuerySet[Case]) -> list[JobRow]:
    fields = (
        "pk",
        "case_id",
        "cobot_id",
        "cobot__name",
        "state",
        "queued_at",
        "started_at",
        "ended_at",
        "accepted_at",
    )
    # The cobots' jobs: a device's calls run in its own queue and keep no cobot busy.
    jobs = Job.objects.filter(case__in=cases, cobot__isnull=False).order_by("queued_at", "pk")
    return [JobRow(*row) for row in jobs.values_list(*fields)]


def interruption_rows(cases: QuerySet[Case]) -> list[InterruptionRow]:
    fields = (
        "pk", "case_id", "work_item_id", "work_item__actor", "by_work_item_id",
        "by_work_item__task", "by_work_item__label", "by_work_item__actor", "cobot_id", "cobot__name",
        "mode", "started_at", "ended_at", "paused_at", "resumed_at",
    )  # fmt: skip
    interruptions = Interruption.objects.filter(case__in=cases).order_by("started_at", "pk")
    return [InterruptionRow(*row) for row in interruptions.values_list(*fields)]


# Measured times, for a prediction (hrc.patterns.prediction) -------------------------------


# A prediction reads the latest cases: how the plant works now, and a request's cost that does
# not grow with the pattern's history.
MEASURED_CASES = 1000


def measured_times(pattern: PatternModel) -> Measured:
    """What the latest MEASURED_CASES completed cases of the pattern's versions, run in its
    organisation, measured:
    each completed task's work time (metrics.item_work_seconds: a cobot task's from its
    cobot's acceptance of the step) by task id and by label, and how often each silent
    transition fired (the log's transition-fired events) with the silent transitions those
    versions had."""
    cases = Case.objects.filter(
        pk__in=Case.objects.filter(
            version__pattern=pattern,
            organisation_id=pattern.organisation_id,
            status=CaseStatus.COMPLETED,
        ).order_by("-ended_at", "-pk")[:MEASURED_CASES]
    )
    by_task: dict[str, list[float]] = {}
    by_label: dict[str, list[float]] = {}
    for item in item_rows(cases):
        seconds = item_work_seconds(item) if item.state == COMPLETED else None
        if seconds is None:
            continue
        by_task.setdefault(item.task, []).append(seconds)
        by_label.setdefault(item.label or item.task, []).append(seconds)
    fired = dict(
        CaseEvent.objects.filter(case__in=cases, type=EventType.TRANSITION_FIRED)
        .order_by()  # the model's ordering would split the groups
        .values("task")
        .annotate(count=Count("pk"))
        .values_list("task", "count")
    )
    return Measured(by_task, by_label, fired, _silent_transitions(pattern, cases))


def _silent_transitions(pattern: PatternModel, cases: QuerySet[Case]) -> frozenset[str]:
    """The silent transitions of the versions that have completed cases."""
    versions = PatternVersion.objects.filter(pattern=pattern, cases__in=cases).distinct()
    silent: set[str] = set()
    for version in versions:
        read = _pattern(version)
        if read is not None:
            silent.update(t.id for _, t in read.transitions() if not t.is_task)
    return frozenset(silent)


# A case's Gantt chart -----------------------------------------------------------------------


def case_gantt(case: Case, *, now: dt.datetime) -> Gantt:
    """The chart of the case: its actors in document order, who performs each, its work
    items, its version's constraints and its interruptions."""
    cases = Case.objects.filter(pk=case.pk)
    pattern = _pattern(case.version)
    actors = pattern.actors if pattern is not None else ()
    constraints = pattern.constraints if pattern is not None else ()
    who = performers(case.actor_mapping)
    return build_gantt(
        case.pk,
        started_at=case.started_at,
        ended_at=case.ended_at,
        now=now,
        actors=[ActorRow(a.id, a.type, who.get(a.id, "")) for a in actors],
        items=item_rows(cases),
        constraints=[
            ConstraintRow(index, c.source, c.target, c.type) for index, c in enumerate(constraints)
        ],
        interruptions=interruption_rows(cases),
    )


def performers(mapping: dict[str, Any]) -> dict[str, str]:
    """Who performs each actor, by name: "olivia, tom", "team Early shift", "ur5e-left".

    The mapping holds ids (hrc.cases.mapping); a row deleted since reads as its id.
    """
    users: set[int] = set()
    teams: set[int] = set()
    cobots: set[int] = set()
    bindings = {actor: b for actor, b in mapping.items() if isinstance(b, dict)}
    for binding in bindings.values():
        users.update(_ids(binding.get("users")))
        teams.update(_ids([binding.get("team")]))
        cobots.update(_ids([binding.get("cobot")]))
    user_names = dict(User.objects.filter(pk__in=users).values_list("pk", "username"))
    team_names = dict(Team.objects.filter(pk__in=teams).values_list("pk", "name"))
    cobot_names = dict(Cobot.objects.filter(pk__in=cobots).values_list("pk", "name"))
    who = {}
    for actor, binding in bindings.items():
        if binding.get("cobot") is not None:
            who[actor] = str(cobot_names.get(binding["cobot"], binding["cobot"]))
        elif binding.get("team") is not None:
            who[actor] = f"team {team_names.get(binding['team'], binding['team'])}"
        else:
            who[actor] = ", ".join(str(user_names.get(u, u)) for u in binding.get("users") or [])
    return who


def _ids(values: Any) -> list[int]:
    if not isinstance(values, list):
        return []
    return [v for v in values if isinstance(v, int) and not isinstance(v, bool)]


# The XES export -----------------------------------------------------------------------------


@dataclass(frozen=True)
class LogSelection:
    """Which cases go into an export, and what the log is called."""

    cases: QuerySet[Case]
    name: str
    filename: str


def xes_log(selection: LogSelection, lifecycle: xes.Lifecycle) -> Iterator[str]:
    """The selection's cases as an XES document, a chunk per trace; both the cases and their
    events are read through server-side cursors, so memory stays flat however many."""
    case_fields = ("pk", "status", "version__number", "version__pattern__name")
    cases = selection.cases.order_by("pk").values_list(*case_fields)
    trace_rows = (
        xes.TraceRow(
            pk,
            (("concept:name", str(pk)), ("pattern", name), ("version", number), ("status", status)),
        )
        for pk, status, number, name in cases.iterator(chunk_size=STREAM_BATCH)
    )
    event_fields = (
        "case_id", "seq", "at", "type", "task", "actor", "work_item_id", "work_item__label",
        "work_item__kind", "work_item__cobot__name", "user__username", "detail",
    )  # fmt: skip
    events = (
        CaseEvent.objects.filter(case__in=selection.cases.values("pk"), type__in=xes.EXPORTED_TYPES)
        .order_by("case_id", "seq")
        .values_list(*event_fields)
    )
    event_rows = (_event_row(*row) for row in events.iterator(chunk_size=STREAM_BATCH))
    log_attributes: list[xes.Attribute] = [
        ("concept:name", selection.name),
        ("lifecycle:model", "standard"),
        ("source", "hrc"),
    ]
    return xes.write_log(log_attributes, xes.traces(trace_rows, event_rows, lifecycle))


def _event_row(
    case_id: int, seq: int, at: dt.datetime, type_: str, task: str, actor: str,
    item_id: int | None, label: str | None, kind: str | None, cobot: str | None,
    user: str | None, detail: Any,
) -> xes.EventRow:  # fmt: skip
    resource = user or cobot or ""  # who did it: the person, else the cobot of a cobot task
    details = detail if isinstance(detail, dict) else {}
    return xes.EventRow(
        case_id, seq, at, type_, task, label or task, actor, kind or "", item_id, resource, details
    )
