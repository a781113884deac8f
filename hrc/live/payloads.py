"""Every payload the tablets get, one builder per event type from one row shape.

A snapshot reads its rows with `.values(*FIELDS)`; a delta turns the object
its caller holds into the same row (`*_row`), with no query. Both then go
through the same builder, so applying deltas to an old snapshot gives the
fresh one (tests/live/test_event_stream.py).
"""

from __future__ import annotations

import datetime as dt
import time
from collections.abc import Mapping
from typing import Any, TypedDict

from django.contrib.auth.models import User

from hrc.cases.models import Case, WorkItem
from hrc.cases.nets import compiled_net
from hrc.cobots.models import CellStop
from hrc.live.events import (
    CaseData,
    CellStopData,
    CobotQueueData,
    CurrentStep,
    IncidentData,
    LiveEvent,
    TimerData,
    WorkItemData,
)

_INCIDENT_EVENTS = frozenset({"incident-opened", "incident-resolved"})
_TIMER_EVENTS = frozenset({"timer-armed", "timer-fired", "timer-disarmed"})


def now() -> float:
    """The `at` of a whole-state payload: the newest wins on the tablet."""
    return time.time()


# Rows: what a snapshot reads and what a delta makes of its objects ----------------------


class CaseRow(TypedDict):
    id: int
    last_seq: int
    status: str
    name: str | None  # the pattern's name, read along with the case
    actor_mapping: Any


class WorkItemRow(TypedDict):
    id: int
    case_id: int
    task: str
    label: str
    actor: str
    kind: str
    state: str
    instructions: str
    team_id: int | None
    cobot_id: int | None
    claimed_by_id: int | None
    offered_at: dt.datetime
    started_at: dt.datetime | None
    in_area: bool  # annotated by the snapshot's query (selectors._work_items)


class IncidentRow(TypedDict):
    id: int
    case_id: int
    work_item_id: int | None
    kind: str
    message: str
    resolution: str


class TimerRow(TypedDict):
    case_id: int
    transition: str
    label: str
    due_at: dt.datetime


WORK_ITEM_FIELDS = tuple(WorkItemRow.__annotations__)
INCIDENT_FIELDS = tuple(IncidentRow.__annotations__)
TIMER_FIELDS = tuple(TimerRow.__annotations__)


def case_row(case: Case) -> CaseRow:
    return {
        "id": case.pk,
        "last_seq": case.last_seq,
        "status": case.status,
        "name": _case_name(case),
        "actor_mapping": case.actor_mapping,
    }


def _case_name(case: Case) -> str:
    # Only from what is in hand (the compiled net, or a version read along): never a query.
    net = compiled_net(case.version_id)
    if net is not None:
        return net.pattern.name
    if not Case.version.is_cached(case):
        return ""
    return str((case.version.document or {}).get("name") or "")


def work_item_row(
    item: WorkItem, *, started_by: User | None = None, in_area: bool = False
) -> WorkItemRow:
    claimed_by = item.claimed_by_id
    if claimed_by is None and started_by is not None and item.kind == "operator":
        claimed_by = started_by.pk  # starting claims it; the service sets it after the event
    return {
        "id": item.pk,
        "case_id": item.case_id,
        "task": item.task,
        "label": item.label,
        "actor": item.actor,
        "kind": item.kind,
        "state": item.state,
        "instructions": item.instructions,
        "team_id": item.team_id,
        "cobot_id": item.cobot_id,
        "claimed_by_id": claimed_by,
        "offered_at": item.offered_at,
        "started_at": item.started_at,
        "in_area": in_area,
    }


def incident_row(case: Case, item: WorkItem | None, detail: Mapping[str, Any]) -> IncidentRow:
    """The incident an `incident-*` event's detail describes."""
    return {
        "id": int(detail.get("incident") or 0),
        "case_id": case.pk,
        "work_item_id": item.pk if item is not None else None,
        "kind": str(detail.get("kind") or ""),
        "message": str(detail.get("message") or ""),
        "resolution": str(detail.get("resolution") or ""),
    }


def timer_row(case: Case, detail: Mapping[str, Any]) -> TimerRow:
    """The timer a `timer-*` event's detail describes (progress._timer_detail)."""
    transition = str(detail.get("transition") or "")
    return {
        "case_id": case.pk,
        "transition": transition,
        "label": str(detail.get("label") or transition),
        "due_at": dt.datetime.fromisoformat(str(detail["due_at"])),
    }


# One builder per payload ---------------------------------------------------------------


def case_data(row: CaseRow) -> CaseData:
    return {
        "id": row["id"],
        "seq": row["last_seq"],
        "status": row["status"],
        "name": row["name"] or "",
        "cobots": cobots_of_mapping(row["actor_mapping"]),
    }


def work_item_data(row: WorkItemRow, mapping: Mapping[str, Any] | None) -> WorkItemData:
    """The item; `mapping` is its case's actor mapping (who an operator task is offered to)."""
    operator = row["kind"] == "operator"
    return {
        "id": row["id"],
        "case": row["case_id"],
        "task": row["task"],
        "label": row["label"],
        "actor": row["actor"],
        "kind": row["kind"],
        "state": row["state"],
        "instructions": row["instructions"],
        "team": row["team_id"],
        "cobot": row["cobot_id"],
        "candidates": candidates_of(mapping, row["actor"]) if operator else [],
        "claimed_by": row["claimed_by_id"],
        "offered_at": row["offered_at"].isoformat(),
        "started_at": row["started_at"].isoformat() if row["started_at"] else None,
        "in_area": row["in_area"],
    }


def incident_data(row: IncidentRow) -> IncidentData:
    return {
        "id": row["id"],
        "case": row["case_id"],
        "work_item": row["work_item_id"],
        "kind": row["kind"],
        "message": row["message"],
        "resolution": row["resolution"],
    }


def timer_data(row: TimerRow) -> TimerData:
    return {
        "case": row["case_id"],
        "transition": row["transition"],
        "label": row["label"] or row["transition"],
        "due_at": row["due_at"].isoformat(),
    }


def cobot_queue_data(
    cobot_id: int, length: int, current: CurrentStep | None, waiting: str | None, at: float
) -> CobotQueueData:
    """The cobot's queue: how many jobs it has (queued and running), the one it runs, and why its
    first waiting job waits ("" when none says)."""
    return {
        "cobot": cobot_id,
        "at": at,
        "queue_length": length,
        "current": current,
        "waiting_for": waiting or "",
    }


def stop_data(stop: CellStop) -> CellStopData:
    """A STOP, with its users read along (select_related) where the caller can."""
    return {
        "id": stop.pk,
        "cell": stop.cell,
        "at": now(),
        "stopped_by": stop.stopped_by.get_username() if stop.stopped_by else "",
        "stopped_at": stop.stopped_at.isoformat(),
        "resumed_by": stop.resumed_by.get_username() if stop.resumed_by else "",
        "resumed_at": stop.resumed_at.isoformat() if stop.resumed_at else None,
        "cobots": list(stop.cobots),
        "problems": dict(stop.problems),
    }


def cobots_of_mapping(mapping: Mapping[str, Any] | None) -> list[int]:
    """The cobots a case's actor mapping names, in id order."""
    return sorted(
        {
            int(binding["cobot"])
            for binding in (mapping or {}).values()
            if isinstance(binding, Mapping) and binding.get("cobot") is not None
        }
    )


def candidates_of(mapping: Mapping[str, Any] | None, actor: str) -> list[int]:
    """The users an operator actor is mapped to (the rule the case services offer by)."""
    binding = (mapping or {}).get(actor)
    if not isinstance(binding, Mapping):
        return []
    return sorted(int(user) for user in binding.get("users") or ())


# A case event's delta ------------------------------------------------------------------


def case_delta(
    case: Case,
    event: str,
    item: WorkItem | None,
    user: User | None,
    detail: Mapping[str, Any] | None,
) -> LiveEvent:
    """The delta for a case event just recorded (case.last_seq is its number). No query."""
    seq = case.last_seq
    if event in _INCIDENT_EVENTS:
        incident = incident_data(incident_row(case, item, detail or {}))
        return {"type": "incident", "case": case.pk, "seq": seq, "event": event,
                "incident": incident}  # fmt: skip
    if event in _TIMER_EVENTS:
        timer = timer_data(timer_row(case, detail or {}))
        return {"type": "timer", "case": case.pk, "seq": seq, "event": event, "timer": timer}
    if item is not None:
        started_by = user if event == "task-started" else None
        # Only its cancellation says a task holds the area; what it does next (area-left) ends it.
        in_area = event == "task-cancelled" and bool((detail or {}).get("in_area"))
        row = work_item_row(item, started_by=started_by, in_area=in_area)
        data = work_item_data(row, case.actor_mapping)
        return {"type": "work-item", "case": case.pk, "seq": seq, "event": event, "item": data}
    return {"type": "case", "case": case.pk, "seq": seq, "event": event,
            "data": case_data(case_row(case))}  # fmt: skip
