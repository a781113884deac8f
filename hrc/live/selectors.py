"""Reads for the tablets: who may watch what, the snapshot, and cobot queues.

The snapshot's rows go through the same builders as the deltas
(hrc.live.payloads), so that applying a tablet's deltas to an old snapshot
gives the fresh one; tests/live/test_event_stream.py checks it.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from typing import Any

from django.db import connection
from django.db.models import BooleanField, Exists, ExpressionWrapper, OuterRef, Q
from django.db.models.fields.json import KeyTextTransform

from hrc.cases.choices import (
    COMMANDED_MODES,
    OPEN_CASE_STATUSES,
    OPEN_WORK_ITEM_STATES,
    JobState,
    TimerState,
    WorkItemState,
)
from hrc.cases.models import Case, CaseTimer, Incident, Interruption, Job, WorkItem
from hrc.cobots.models import CellStop, Cobot
from hrc.live import cobot_states, payloads
from hrc.live.events import (
    CaseData,
    CellStopData,
    CobotData,
    CobotQueueData,
    CurrentStep,
    FloorCobot,
    IncidentData,
    Snapshot,
    TimerData,
    WorkItemData,
)
from hrc.live.payloads import INCIDENT_FIELDS, TIMER_FIELDS, WORK_ITEM_FIELDS
from hrc.organisations.models import Membership, Organisation, Team
from hrc.organisations.selectors import AnyUser, cells_of


@dataclass(frozen=True)
class Access:
    """What a socket's user is in the organisation it watches."""

    user_id: int
    username: str
    organisation_id: int
    role: str


def access_of(user: AnyUser, organisation_id: int | None) -> Access | None:
    """The user's access to the organisation; None for a non-member (or an anonymous user).

    With no organisation given, the user's only one (or the first by name).
    """
    if not user.is_authenticated or not user.is_active:
        return None
    memberships = Membership.objects.filter(user_id=user.pk).order_by("organisation__name")
    if organisation_id is not None:
        memberships = memberships.filter(organisation_id=organisation_id)
    found = memberships.values_list("organisation_id", "role").first()
    if found is None:
        return None
    return Access(user.pk, user.get_username(), found[0], found[1])


def is_cell(organisation_id: int, cell: str) -> bool:
    """Whether `cell` is one of the organisation's cells; "" (the whole floor) always is."""
    return not cell or cells_of(organisation_id).filter(name=cell).exists()


def organisation_name(organisation_id: int) -> str:
    return Organisation.objects.filter(pk=organisation_id).values_list("name", flat=True).get()


def valid_memberships(pairs: set[tuple[int, int]]) -> set[tuple[int, int]]:
    """Those of the (user, organisation) pairs that are still memberships of an active user."""
    if not pairs:
        return set()
    users = {user for user, _ in pairs}
    organisations = {organisation for _, organisation in pairs}
    found = Membership.objects.filter(
        user_id__in=users, organisation_id__in=organisations, user__is_active=True
    ).values_list("user_id", "organisation_id")
    return set(found) & pairs


def snapshot(access: Access, cell: str) -> Snapshot:
    """Everything a tablet shows, as of now. Cases are read first: a change that lands while
    the rest is read is then newer than the case's seq, and its delta is applied on top."""
    organisation = access.organisation_id
    cases, mappings = _open_cases(organisation)
    case_ids = [case["id"] for case in cases]
    # Every cobot of the organisation: its cell's tablet shows some, and names the others' cells.
    floor = list(
        Cobot.objects.filter(organisation_id=organisation)
        .order_by("name")
        .values("id", "name", "cell", "stopped_at")
    )
    cobot_rows = [row for row in floor if not cell or row["cell"] == cell]
    ids = [row["id"] for row in cobot_rows]
    queues = {data["cobot"]: data for _, _, data in cobot_queues(ids)}
    states = cobot_states.recall(ids)
    teams = Team.objects.filter(
        organisation_id=organisation, members__user_id=access.user_id
    ).values_list("pk", flat=True)
    return {
        "type": "snapshot",
        "organisation": organisation,
        "cell": cell,
        "user": {
            "id": access.user_id,
            "username": access.username,
            "role": access.role,
            "teams": sorted(teams),
        },
        "cases": cases,
        "work_items": _open_work_items(case_ids, mappings),
        "incidents": _open_incidents(case_ids),
        "timers": _armed_timers(case_ids),
        "cobots": [
            CobotData(
                id=row["id"],
                name=row["name"],
                cell=row["cell"],
                stopped=row["stopped_at"] is not None,
                state=states.get(row["id"]),
                queue=queues[row["id"]],
            )
            for row in cobot_rows
        ],
        "floor": [
            FloorCobot(id=row["id"], name=row["name"], cell=row["cell"])
            for row in sorted(floor, key=lambda row: row["id"])
        ],
        "stop": active_stop(organisation, cell),
    }


def _open_cases(organisation: int) -> tuple[list[CaseData], dict[int, Any]]:
    """The organisation's open cases, and each one's actor mapping."""
    rows = list(
        Case.objects.filter(organisation_id=organisation, status__in=sorted(OPEN_CASE_STATUSES))
        .annotate(name=KeyTextTransform("name", "version__document"))
        .order_by("id")
        .values("id", "last_seq", "status", "name", "actor_mapping")
    )
    cases = [payloads.case_data(row) for row in rows]  # type: ignore[arg-type]
    return cases, {row["id"]: row["actor_mapping"] for row in rows}


def _open_work_items(case_ids: list[int], mappings: dict[int, Any]) -> list[WorkItemData]:
    """The open items, and the cancelled ones whose operator may still be in the area."""
    holding = Interruption.objects.filter(
        by_work_item=OuterRef("pk"), mode__in=sorted(COMMANDED_MODES), ended_at__isnull=True
    )
    in_area = Q(state=WorkItemState.CANCELLED) & Exists(holding)
    rows = (
        WorkItem.objects.filter(case_id__in=case_ids)
        .annotate(in_area=ExpressionWrapper(in_area, output_field=BooleanField()))
        .filter(Q(state__in=sorted(OPEN_WORK_ITEM_STATES)) | Q(in_area=True))
        .order_by("offered_at", "id")
        .values(*WORK_ITEM_FIELDS)
    )
    return [payloads.work_item_data(row, mappings.get(row["case_id"])) for row in rows]


def _armed_timers(case_ids: list[int]) -> list[TimerData]:
    rows = (
        CaseTimer.objects.filter(case_id__in=case_ids, state=TimerState.ARMED)
        .order_by("due_at", "case_id", "transition")  # as the tablet's store sorts them
        .values(*TIMER_FIELDS)
    )
    return [payloads.timer_data(row) for row in rows]


def _open_incidents(case_ids: list[int]) -> list[IncidentData]:
    rows = (
        Incident.objects.filter(case_id__in=case_ids, resolved_at__isnull=True)
        .order_by("id")
        .values(*INCIDENT_FIELDS)
    )
    return [payloads.incident_data(row) for row in rows]


def cobot_queues(cobot_ids: list[int]) -> list[tuple[int, str, CobotQueueData]]:
    """(organisation, cell, queue) per cobot, in the order given: one statement whatever the count.

    Plain SQL: the sender runs it for every lease and finish, and the ORM's row building cost
    more than the query itself. The database counts the queue and finds its running job and
    first reason to wait: a row per cobot, however long its queue (1000 queued jobs read
    row by row cost more than the cases' own statements; bench/README.md, "Cobot queues").
    """
    if not cobot_ids:
        return []
    marks = ", ".join(["%s"] * len(cobot_ids))
    queued, running = JobState.QUEUED.value, JobState.RUNNING.value
    with connection.cursor() as cursor:
        cursor.execute(
            _COBOT_QUEUES_SQL.format(marks=marks), [queued, running, queued, running, *cobot_ids]
        )
        rows = {row[0]: row[1:] for row in cursor.fetchall()}
    at = payloads.now()
    found = []
    for pk in cobot_ids:
        if pk not in rows:
            continue
        organisation, cell, length, waiting, *job = rows[pk]
        current = _current_step(*job) if job[0] is not None else None
        found.append(
            (organisation, cell, payloads.cobot_queue_data(pk, length, current, waiting, at))
        )
    return found


# Each cobot with the length of its queue (queued and running jobs), the first reason a queued
# job gives for waiting, in queue order, and its running job, if any. Portable SQL (SQLite is
# the embedded default). The names formatted in are the models' tables; every value is a
# parameter.
_JOB, _ITEM = Job._meta.db_table, WorkItem._meta.db_table
_COBOT_QUEUES_SQL = f"""
    SELECT c.id, c.organisation_id, c.cell, c.length, c.waiting,
           r.case_id, r.work_item_id, r.kind, r.attempt, r.command, w.task, w.label
    FROM (
        SELECT c.id, c.organisation_id, c.cell,
               (SELECT count(*) FROM {_JOB} q
                WHERE q.cobot_id = c.id AND q.state IN (%s, %s)) AS length,
               (SELECT q.waiting_for FROM {_JOB} q
                WHERE q.cobot_id = c.id AND q.state = %s AND q.waiting_for <> ''
                ORDER BY q.queued_at, q.id LIMIT 1) AS waiting,
               (SELECT q.id FROM {_JOB} q WHERE q.cobot_id = c.id AND q.state = %s
                ORDER BY q.queued_at DESC, q.id DESC LIMIT 1) AS running
        FROM {Cobot._meta.db_table} c
        WHERE c.id IN ({{marks}})
    ) c
    LEFT JOIN {_JOB} r ON r.id = c.running
    LEFT JOIN {_ITEM} w ON w.id = r.work_item_id
"""


def _current_step(
    case: int, item: int, kind: str, attempt: int, command: Any, task: str, label: str
) -> CurrentStep:
    """The running job of a cobot, and the program step number of its command."""
    if isinstance(command, str):  # a raw cursor hands JSON back as text
        command = json.loads(command)
    number = (command or {}).get("number")
    return {
        "case": case, "work_item": item, "task": task, "label": label, "kind": kind,
        "step": int(number) if isinstance(number, int) else None, "attempt": attempt,
    }  # fmt: skip


def active_stop(organisation: int, cell: str) -> CellStopData | None:
    """The STOP holding the cell, or the whole floor's when the cell has none."""
    stops = CellStop.objects.filter(organisation_id=organisation, resumed_at__isnull=True)
    stop = stops.filter(cell=cell).select_related("stopped_by", "resumed_by").first()
    if stop is None and cell:
        stop = stops.filter(cell="").select_related("stopped_by", "resumed_by").first()
    return payloads.stop_data(stop) if stop is not None else None
