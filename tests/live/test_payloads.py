"""One builder per payload: a delta made from the objects a service holds equals what a snapshot
makes of the same rows read afresh."""

from __future__ import annotations

from typing import Any

import pytest
from django.contrib.auth.models import User

from hrc.cases import progress, services
from hrc.cobots.models import Cobot
from hrc.live import groups, payloads
from hrc.live.selectors import access_of, snapshot
from hrc.organisations.models import Organisation
from tests import factories
from tests.cases import patterns

pytestmark = pytest.mark.django_db


@pytest.fixture
def deltas(monkeypatch: pytest.MonkeyPatch) -> list[dict[str, Any]]:
    """The deltas the case services published, in order (their send after commit left out)."""
    sent: list[dict[str, Any]] = []
    monkeypatch.setattr(groups, "send_event_on_commit", lambda g, event, **kw: sent.append(event))
    return sent


def test_deltas_and_the_snapshot_build_cases_work_items_and_incidents_alike(
    organisation: Organisation,
    engineer: User,
    operator: User,
    cobot: Cobot,
    deltas: list[dict[str, Any]],
) -> None:
    version = factories.make_version(organisation, published_by=engineer)
    case = factories.hand_over_case(version, started_by=engineer, operator=operator, cobot=cobot)
    access = access_of(operator, organisation.pk)
    assert access is not None

    items = snapshot(access, "")["work_items"]
    latest = {d["item"]["id"]: d["item"] for d in deltas if d["type"] == "work-item"}
    assert items
    assert [latest[item["id"]] for item in items] == items

    factories.make_incident(factories.open_work_item(case, "tc1"))
    [incident] = snapshot(access, "")["incidents"]
    assert deltas[-1] == {
        "type": "incident", "case": case.pk, "seq": deltas[-1]["seq"],
        "event": "incident-opened", "incident": incident,
    }  # fmt: skip

    locked = progress.lock_case(case.pk)
    [shown] = snapshot(access, "")["cases"]
    assert payloads.case_data(payloads.case_row(locked)) == shown


def test_timer_deltas_keep_the_armed_timers_the_snapshot_lists(
    organisation: Organisation, engineer: User, operator: User, deltas: list[dict[str, Any]]
) -> None:
    version = factories.make_version(
        organisation, published_by=engineer, draft=patterns.inspection_with_deadline()
    )
    case = services.start_case(
        version, started_by=operator, actor_mapping={"o": {"users": [operator.pk]}}
    )
    access = access_of(operator, organisation.pk)
    assert access is not None

    [armed] = [d for d in deltas if d["type"] == "timer"]
    [timer] = snapshot(access, "")["timers"]
    assert armed == {
        "type": "timer", "case": case.pk, "seq": armed["seq"], "event": "timer-armed",
        "timer": timer,
    }  # fmt: skip
    assert timer["transition"] == "late"

    item = factories.open_work_item(case, "to1")
    services.start_work_item(item, user=operator)
    services.complete_work_item(item, user=operator)
    [_, disarmed] = [d for d in deltas if d["type"] == "timer"]
    assert (disarmed["event"], disarmed["timer"]) == ("timer-disarmed", timer)
    assert snapshot(access, "")["timers"] == []
