"""GET /api/analytics/cases/{id}/gantt/: rows per actor, bars per work item, arrows per
constraint between the bars of its tasks, interruptions marked."""

from typing import Any

import pytest
from django.contrib.auth.models import User
from rest_framework.test import APIClient

from hrc.cases.models import WorkItem
from hrc.cobots.models import Cobot
from hrc.patterns.models import PatternVersion
from tests.analytics.running import (
    operator_does,
    pin,
    pin_interruption,
    run_hand_over,
    run_shared_space,
)
from tests.factories import make_case

pytestmark = pytest.mark.django_db


def gantt(client: APIClient, case_id: int) -> Any:
    """The chart as JSON (nested dicts and lists)."""
    response = client.get(f"/api/analytics/cases/{case_id}/gantt/")
    assert response.status_code == 200, response.content
    return response.json()


def test_a_hand_over_is_a_bar_per_task_in_its_actors_row_and_a_time_arrow_between(
    engineer_client: APIClient,
    hand_over: PatternVersion,
    engineer: User,
    operator: User,
    cobot: Cobot,
) -> None:
    case = run_hand_over(hand_over, engineer, operator, cobot)
    pin(case, started=0, ended=100, items={"to1": (0, 10, 40), "tc1": (40, 50, 100)})
    body = gantt(engineer_client, case.pk)
    assert (body["case"], body["open"], body["start"], body["end"]) == (
        case.pk,
        False,
        "2025-03-01T08:00:00Z",
        "2025-03-01T08:01:40Z",
    )
    rows = body["rows"]
    assert [(r["actor"], r["type"], r["who"], r["lanes"]) for r in rows] == [
        ("c", "cobot", "ur5e-left", 1),
        ("o", "operator", "olivia-operator", 1),
    ]
    (placing,) = rows[0]["bars"]
    (preparing,) = rows[1]["bars"]
    items = {i.task: i.pk for i in WorkItem.objects.filter(case=case)}
    assert (preparing["work_item"], preparing["task"], preparing["state"]) == (
        items["to1"],
        "to1",
        "completed",
    )
    assert (preparing["resource"], placing["resource"]) == ("olivia-operator", "ur5e-left")
    assert (placing["offered_at"], placing["started_at"], placing["ended_at"]) == (
        "2025-03-01T08:00:40Z",
        "2025-03-01T08:00:50Z",
        "2025-03-01T08:01:40Z",
    )
    assert body["constraints"] == [{"index": 0, "source": "to1", "target": "tc1", "type": "time"}]
    (arrow,) = body["arrows"]
    assert (arrow["constraint"], arrow["type"], arrow["overlapping"]) == (0, "time", False)
    assert (arrow["from_work_item"], arrow["to_work_item"]) == (items["to1"], items["tc1"])
    assert (arrow["from_at"], arrow["to_at"]) == ("2025-03-01T08:00:40Z", "2025-03-01T08:00:50Z")
    assert body["marks"] == []


def test_a_shared_space_marks_the_interruption_on_the_cobots_bar(
    engineer_client: APIClient,
    shared: PatternVersion,
    engineer: User,
    operator: User,
    cobot: Cobot,
) -> None:
    case = run_shared_space(shared, engineer, operator, cobot)
    pin(case, started=0, ended=60,
        items={"to1": (0, 1, 5), "tc1": (5, 6, 60), "to2": (5, 10, 35)})  # fmt: skip
    interruption = pin_interruption(case, 10, 35)
    body = gantt(engineer_client, case.pk)
    items = {i.task: i.pk for i in WorkItem.objects.filter(case=case)}
    operator_row = body["rows"][1]
    assert [(b["task"], b["lane"]) for b in operator_row["bars"]] == [("to1", 0), ("to2", 0)]
    (arrow,) = body["arrows"]
    assert (arrow["type"], arrow["from_work_item"], arrow["to_work_item"]) == (
        "space",
        items["to2"],
        items["tc1"],
    )
    assert arrow["overlapping"] is True  # both ran at once: the moment the cobot was paused
    assert arrow["from_at"] == arrow["to_at"] == "2025-03-01T08:00:10Z"
    (mark,) = body["marks"]
    assert (mark["interruption"], mark["work_item"], mark["by_work_item"]) == (
        interruption.pk,
        items["tc1"],
        items["to2"],
    )
    assert (mark["mode"], mark["cobot"]) == ("pause", "ur5e-left")
    assert (mark["started_at"], mark["ended_at"]) == (
        "2025-03-01T08:00:10Z",
        "2025-03-01T08:00:35Z",
    )


def test_a_running_case_has_open_bars_a_waiting_task_and_no_arrow_yet(
    engineer_client: APIClient,
    hand_over: PatternVersion,
    engineer: User,
    operator: User,
    cobot: Cobot,
) -> None:
    ahead, case = (
        make_case(
            hand_over,
            started_by=engineer,
            actor_mapping={"o": {"users": [operator.pk]}, "c": {"cobot": cobot.pk}},
        )
        for _ in range(2)
    )
    operator_does(ahead, "to1", operator)  # its step takes the free cobot
    operator_does(case, "to1", operator)  # the step is queued: its task is offered, not started
    body = gantt(engineer_client, case.pk)
    assert body["open"] is True
    (queued,) = body["rows"][0]["bars"]
    assert (queued["state"], queued["started_at"], queued["ended_at"]) == ("offered", None, None)
    assert body["arrows"] == []  # the constraint's target has not started
    assert body["end"] == body["now"]
