"""The case event log and incidents, and the one hook through which cases publish to the tablets.

Cases never import the live app: it registers its side here once Django is
ready (hrc.live.receivers). Until something is registered, publishing does
nothing, so cases run the same without tablets.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any, Protocol

from django.contrib.auth.models import User
from django.utils import timezone

from hrc.cases.choices import EventType, IncidentKind
from hrc.cases.models import Case, CaseEvent, Incident, WorkItem
from hrc.engine.petri import Marking


class CaseEventHook(Protocol):
    """Publishes, after commit, the event just recorded (case.last_seq is its number).

    Called inside the transaction while the case row lock is held: it queries nothing."""

    def __call__(
        self,
        case: Case,
        event: str,
        item: WorkItem | None,
        user: User | None,
        detail: Mapping[str, Any] | None,
    ) -> None: ...


class Hold(Protocol):
    def release(self) -> None: ...


# Publishes, after commit, that a cobot's queue changed.
CobotQueueHook = Callable[[int], None]
# Keeps this process's publishing back until released (a worker sends the step first).
HoldHook = Callable[[], Hold]


class _NoHold:
    def release(self) -> None:
        pass


def _no_case_event(
    case: Case,
    event: str,
    item: WorkItem | None,
    user: User | None,
    detail: Mapping[str, Any] | None,
) -> None:
    pass


def _no_cobot_queue(cobot_id: int) -> None:
    pass


@dataclass
class _Publisher:
    case_event: CaseEventHook = _no_case_event
    cobot_queue: CobotQueueHook = _no_cobot_queue
    hold: HoldHook = _NoHold


_PUBLISHER = _Publisher()


def register_publisher(
    *, case_event: CaseEventHook, cobot_queue: CobotQueueHook, hold: HoldHook
) -> None:
    """Called once by the app that serves the tablets, from its receivers.py."""
    _PUBLISHER.case_event = case_event
    _PUBLISHER.cobot_queue = cobot_queue
    _PUBLISHER.hold = hold


def publish_cobot_queue(cobot_id: int) -> None:
    """Says, after commit, that the cobot's queue changed."""
    _PUBLISHER.cobot_queue(cobot_id)


def hold_publishing() -> Hold:
    """Keeps what this process publishes back until `.release()`; a no-op when nobody listens."""
    return _PUBLISHER.hold()


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

    Call while holding the case row lock; the caller saves the case, which writes the event
    (Case.save: the log and the case in one statement).
    """
    case.last_seq += 1
    _PUBLISHER.case_event(case, event, item, user, detail)  # the tablets, after commit
    marking = dict(case.marking)
    row = CaseEvent(
        case=case, seq=case.last_seq, at=timezone.now(), type=event,
        task=item.task if item else task, actor=item.actor if item else "",
        work_item=item, user=user if user is not None and user.is_authenticated else None,
        marking_before=dict(before) if before is not None else marking,
        marking_after=dict(after) if after is not None else marking,
        detail=dict(detail or {}),
    )  # fmt: skip
    case.log(row)  # written with the case, by the caller's case.save()
    return row


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
