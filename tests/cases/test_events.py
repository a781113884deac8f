"""Cases publish to the tablets through the one hook in hrc.cases.events, which live registers."""

from collections.abc import Mapping
from typing import Any

import pytest
from django.contrib.auth.models import User
from django.db import transaction

from hrc.cases import events
from hrc.cases.choices import EventType
from hrc.cases.models import Case, CaseEvent, WorkItem
from hrc.live import groups


@pytest.fixture
def unregistered(monkeypatch: pytest.MonkeyPatch) -> None:
    """No app listening, as before Django is ready; the live app's registration comes back after."""
    monkeypatch.setattr(events, "_PUBLISHER", events._Publisher())


@pytest.fixture
def published(unregistered: None) -> list[tuple[Any, ...]]:
    """What cases publish while the test runs, instead of the live app's sends."""
    calls: list[tuple[Any, ...]] = []

    def case_event(
        case: Case,
        event: str,
        item: WorkItem | None,
        user: User | None,
        detail: Mapping[str, Any] | None,
    ) -> None:
        # Inside the transaction, before the event's row: the case's counter names it already.
        calls.append(("case_event", case.pk, case.last_seq, event, item, user, detail))
        assert not CaseEvent.objects.filter(case=case, seq=case.last_seq).exists()

    events.register_publisher(
        case_event=case_event,
        cobot_queue=lambda cobot_id: calls.append(("cobot_queue", cobot_id)),
        hold=events._NoHold,
    )
    return calls


def test_the_live_app_registers_its_sends_when_django_is_ready() -> None:
    assert events._PUBLISHER.case_event is groups.case_event_on_commit
    assert events._PUBLISHER.cobot_queue is groups.cobot_queue_on_commit
    assert events._PUBLISHER.hold is groups.hold


@pytest.mark.django_db
def test_each_recorded_event_is_published_with_its_number(
    published: list[tuple[Any, ...]], choice_case: Case, engineer: User
) -> None:
    published.clear()  # the case's start
    with transaction.atomic():
        case = Case.objects.select_for_update().get(pk=choice_case.pk)
        seq = case.last_seq
        row = events.record_event(case, EventType.CASE_SUSPENDED, user=engineer, detail={"x": 1})
        case.save()
    assert published == [
        ("case_event", case.pk, seq + 1, EventType.CASE_SUSPENDED, None, engineer, {"x": 1})
    ]
    assert row.seq == seq + 1


@pytest.mark.django_db
def test_with_nothing_registered_cases_record_events_and_hold_nothing(
    unregistered: None, choice_case: Case, engineer: User
) -> None:
    hold = events.hold_publishing()
    with transaction.atomic():
        case = Case.objects.select_for_update().get(pk=choice_case.pk)
        events.record_event(case, EventType.CASE_SUSPENDED, user=engineer)
        events.publish_cobot_queue(7)
        case.save()
    hold.release()
    hold.release()
    assert CaseEvent.objects.filter(case=case, type=EventType.CASE_SUSPENDED).count() == 1
