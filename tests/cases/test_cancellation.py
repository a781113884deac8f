"""A transition's `cancels` at run time: the running tasks it empties are cancelled. An operator's
leaves the tablets; a cobot's step on the cobot runs on, its end recorded and firing nothing."""

from __future__ import annotations

from typing import Any

import pytest
from django.contrib.auth.models import User
from django.test import Client
from django.urls import reverse
from rest_framework.test import APIClient

from hrc.cases import jobs, services, timers
from hrc.cases.choices import CaseStatus, EventType, InterruptionMode, JobState, WorkItemState
from hrc.cases.messages import receive_message
from hrc.cases.models import Case, CaseEvent, CaseTimer, Incident, Interruption, Job, WorkItem
from hrc.cobots.drivers.base import CommandRefused
from hrc.cobots.models import Cobot
from hrc.errors import Conflict
from hrc.live import groups
from hrc.live.selectors import access_of, snapshot
from hrc.organisations.choices import Role
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


def _start(
    organisation: Organisation, engineer: User, document: dict[str, Any], mapping: dict[str, Any]
) -> Case:
    version = factories.make_version(organisation, published_by=engineer, draft=document)
    # Time scale 0: the timers are due at once; the tests ring them (no worker here).
    return services.start_case(version, started_by=engineer, actor_mapping=mapping, timer_scale=0)


def _ring(case: Case) -> None:
    assert timers.ring_timer(CaseTimer.objects.get(case=case, transition="late").pk)


def _events(case: Case, *types: str) -> list[tuple[str, str, dict[str, Any]]]:
    rows = CaseEvent.objects.filter(case=case, type__in=types).order_by("seq")
    return [(row.type, row.task, row.detail) for row in rows]


def test_a_timer_cancels_the_running_operator_task_which_leaves_the_tablet(
    organisation: Organisation, engineer: User, operator: User, deltas: list[dict[str, Any]]
) -> None:
    case = _start(
        organisation, engineer, patterns.inspection_with_deadline(),
        {"o": {"users": [operator.pk]}},
    )  # fmt: skip
    inspect = factories.open_work_item(case, "to1")
    services.start_work_item(inspect, user=operator)

    _ring(case)

    inspect.refresh_from_db()
    assert inspect.state == WorkItemState.CANCELLED
    assert inspect.ended_at is not None
    assert (EventType.TASK_CANCELLED, "to1", {"by": "late"}) in _events(
        case, EventType.TASK_CANCELLED
    )
    [*_, last] = [d for d in deltas if d["type"] == "work-item" and d["item"]["id"] == inspect.pk]
    assert (last["event"], last["item"]["state"]) == ("task-cancelled", "cancelled")
    access = access_of(operator, organisation.pk)
    assert access is not None
    shown = {item["task"] for item in snapshot(access, "")["work_items"]}
    assert shown == {"to_rework"}
    with pytest.raises(Conflict):
        services.complete_work_item(inspect, user=operator)


def test_a_terminate_cancelling_the_last_running_task_completes_the_case(
    organisation: Organisation, engineer: User, operator: User
) -> None:
    case = _start(
        organisation, engineer, patterns.terminate_on_alarm(), {"o": {"users": [operator.pk]}}
    )
    assemble = factories.open_work_item(case, "to1")
    services.start_work_item(assemble, user=operator)
    alarm = factories.open_work_item(case, "to2")
    services.start_work_item(alarm, user=operator)
    services.complete_work_item(alarm, user=operator)

    case.refresh_from_db()
    assemble.refresh_from_db()
    assert case.status == CaseStatus.COMPLETED
    assert assemble.state == WorkItemState.CANCELLED  # cancelled by terminate, not withdrawn
    assert _events(case, EventType.TASK_CANCELLED, EventType.TASK_WITHDRAWN) == [
        (EventType.TASK_CANCELLED, "to1", {"by": "terminate"})
    ]


@pytest.fixture
def picking(organisation: Organisation, engineer: User, operator: User, cobot: Cobot) -> Case:
    return _start(
        organisation, engineer, patterns.pick_with_deadline(),
        {"o": {"users": [operator.pk]}, "c": {"cobot": cobot.pk}},
    )  # fmt: skip


def test_a_cancelled_step_on_the_cobot_runs_on_and_its_end_fires_nothing(
    picking: Case, cobot: Cobot
) -> None:
    lease = jobs.lease_next_job(cobot.pk)  # the cobot has taken the pick: it runs
    assert lease is not None

    _ring(picking)

    pick = WorkItem.objects.get(case=picking, task="tc1")
    assert pick.state == WorkItemState.CANCELLED
    assert Job.objects.get(work_item=pick).state == JobState.RUNNING  # not stopped
    picking.refresh_from_db()
    marking = dict(picking.marking)

    jobs.finish_job(lease, {"outcome": "ran", "seconds": 2.0})

    picking.refresh_from_db()
    assert Job.objects.get(work_item=pick).state == JobState.SUCCEEDED
    assert picking.marking == marking
    assert _events(picking, EventType.CANCELLED_STEP_ENDED, EventType.TASK_COMPLETED) == [
        (EventType.CANCELLED_STEP_ENDED, "tc1", {"result": {"outcome": "ran", "seconds": 2.0}})
    ]
    # The cobot is free again; the case goes on with the operator.
    assert factories.open_work_item(picking, "to_clear")


def test_a_cancelled_step_that_fails_opens_no_incident(picking: Case, cobot: Cobot) -> None:
    lease = jobs.lease_next_job(cobot.pk)
    assert lease is not None
    _ring(picking)

    jobs.fail_job(lease, CommandRefused("protective stop"))

    pick = WorkItem.objects.get(case=picking, task="tc1")
    assert Job.objects.get(work_item=pick).state == JobState.CANCELLED
    assert not Incident.objects.filter(case=picking).exists()
    assert _events(picking, EventType.CANCELLED_STEP_ENDED) == [
        (EventType.CANCELLED_STEP_ENDED, "tc1", {"error": "protective stop"})
    ]


def test_a_step_not_yet_sent_leaves_the_queue(picking: Case) -> None:
    _ring(picking)

    pick = WorkItem.objects.get(case=picking, task="tc1")
    assert pick.state == WorkItemState.WITHDRAWN  # only offered: its input emptied
    assert Job.objects.get(work_item=pick).state == JobState.CANCELLED
    assert _events(picking, EventType.TASK_WITHDRAWN) == [
        (EventType.TASK_WITHDRAWN, "tc1", {"why": "pick late cancelled it"})
    ]


def test_the_case_history_shows_the_task_cancelled_and_by_what(
    organisation: Organisation, engineer: User, operator: User
) -> None:
    case = _start(
        organisation, engineer, patterns.inspection_with_deadline(),
        {"o": {"users": [operator.pk]}},
    )  # fmt: skip
    services.start_work_item(factories.open_work_item(case, "to1"), user=operator)
    _ring(case)
    client = Client()
    client.force_login(engineer)

    page = client.get(reverse("cases:case-detail", args=[case.pk])).content.decode()

    def row(event: str) -> str:
        return page[page.index(f'data-type="{event}"') :].split("</tr>")[0]

    assert "Task cancelled" in row("task-cancelled")
    assert "inspect <code" in row("task-cancelled")
    assert "by: late" in row("task-cancelled")
    assert "Timer fired" in row("timer-fired")
    assert "running:to1 −1" in row("timer-fired")  # the timer's firing emptied it


def test_a_message_transition_cancels_the_running_task_it_interrupts(
    organisation: Organisation, engineer: User, operator: User
) -> None:
    """An interrupting message boundary event: `late` waits for "abort" instead of a time."""
    document = patterns.inspection_with_deadline()
    [late] = [t for t in document["processes"][0]["transitions"] if t["id"] == "late"]
    del late["timer"]
    late["message"] = {"name": "abort", "correlation": {"case": "case.id"}}
    case = _start(organisation, engineer, document, {"o": {"users": [operator.pk]}})
    inspect = factories.open_work_item(case, "to1")
    services.start_work_item(inspect, user=operator)

    receive_message(organisation, message_id="m1", name="abort", correlation={"case": case.pk})

    inspect.refresh_from_db()
    assert inspect.state == WorkItemState.CANCELLED
    assert _events(case, EventType.TASK_CANCELLED) == [
        (EventType.TASK_CANCELLED, "to1", {"by": "late"})
    ]
    assert factories.open_work_item(case, "to_rework")


# A cancelled operator's presence: the cobot it paused waits for a person ------------------


@pytest.fixture
def beside_cobot(
    organisation: Organisation, engineer: User, operator: User, cobot: Cobot,
    deltas: list[dict[str, Any]],
) -> tuple[Case, WorkItem]:  # fmt: skip
    """The inspection cancelled by its deadline while it paused the cobot's pick (the deltas
    published from the start)."""
    case = _start(
        organisation, engineer, patterns.inspection_beside_cobot_with_deadline(),
        {"o": {"users": [operator.pk]}, "c": {"cobot": cobot.pk}},
    )  # fmt: skip
    assert jobs.lease_next_job(cobot.pk) is not None  # the pick runs on the cobot
    inspect = factories.open_work_item(case, "to2")
    services.start_work_item(inspect, user=operator)
    [pause] = Interruption.objects.filter(case=case, by_work_item=inspect)
    assert (pause.mode, pause.ended_at) == (InterruptionMode.PAUSE, None)
    _ring(case)
    inspect.refresh_from_db()
    assert inspect.state == WorkItemState.CANCELLED
    return case, inspect


def _in_area(operator: User, organisation: Organisation) -> list[tuple[int, str]]:
    """The tablet's items that hold the area, from a fresh snapshot."""
    access = access_of(operator, organisation.pk)
    assert access is not None
    items = snapshot(access, "")["work_items"]
    return [(item["id"], item["state"]) for item in items if item["in_area"]]


def test_the_cobot_paused_for_a_cancelled_operator_stays_paused_until_the_operator_has_left(
    beside_cobot: tuple[Case, WorkItem], operator: User, organisation: Organisation,
    deltas: list[dict[str, Any]],
) -> None:  # fmt: skip
    case, inspect = beside_cobot
    pause = Interruption.objects.get(case=case, by_work_item=inspect)
    assert pause.ended_at is None  # the cancellation alone resumes nothing
    assert not _events(case, EventType.TASK_RESUMED)
    # The operator's tablet keeps the task, asking them to say when they are out.
    assert _in_area(operator, organisation) == [(inspect.pk, "cancelled")]
    [cancelled] = [d for d in deltas if d["event"] == EventType.TASK_CANCELLED]
    assert cancelled["item"]["in_area"] is True

    assert services.confirm_left_area(inspect, by=operator)

    assert _in_area(operator, organisation) == []
    assert deltas[-1]["event"] == EventType.AREA_LEFT
    assert deltas[-1]["item"]["in_area"] is False

    pause.refresh_from_db()
    assert pause.ended_at is not None
    assert [t for t, *_ in _events(case, EventType.TASK_RESUMED, EventType.AREA_LEFT)] == [
        EventType.TASK_RESUMED, EventType.AREA_LEFT,
    ]  # fmt: skip
    ended = pause.ended_at
    assert not services.confirm_left_area(inspect, by=operator)  # a second one does nothing
    pause.refresh_from_db()
    assert pause.ended_at == ended
    assert len(_events(case, EventType.AREA_LEFT)) == 1


def test_only_its_operator_or_a_supervisor_says_the_area_is_clear(
    beside_cobot: tuple[Case, WorkItem], organisation: Organisation, engineer: User,
    outsider: User,
) -> None:  # fmt: skip
    _, inspect = beside_cobot
    url = f"/api/work-items/{inspect.pk}/left-area/"
    other = factories.make_member(organisation, Role.OPERATOR, "oscar-operator")
    for user, status in [(outsider, 404), (other, 403)]:
        client = APIClient()
        client.force_authenticate(user)
        assert client.post(url).status_code == status
    assert Interruption.objects.get(by_work_item=inspect).ended_at is None
    client = APIClient()
    client.force_authenticate(engineer)
    answer = client.post(url)
    assert answer.status_code == 200, answer.content
    assert answer.json()["state"] == "cancelled"
    assert Interruption.objects.get(by_work_item=inspect).ended_at is not None


def test_the_area_is_cleared_only_for_a_cancelled_task(
    organisation: Organisation, engineer: User, operator: User
) -> None:
    case = _start(
        organisation, engineer, patterns.inspection_with_deadline(),
        {"o": {"users": [operator.pk]}},
    )  # fmt: skip
    inspect = factories.open_work_item(case, "to1")
    services.start_work_item(inspect, user=operator)
    with pytest.raises(Conflict, match="was not cancelled"):
        services.confirm_left_area(inspect, by=operator)


def test_a_supervisor_says_so_on_the_case_page(
    beside_cobot: tuple[Case, WorkItem], engineer: User, operator: User
) -> None:
    case, inspect = beside_cobot
    page = reverse("cases:case-detail", args=[case.pk])
    control = reverse("cases:case-control", args=[case.pk])
    client = Client()
    client.force_login(operator)  # no supervisor: refused, as every control of the case
    assert client.post(control, {"action": "left-area", "item": inspect.pk}).status_code == 403
    client.force_login(engineer)
    assert "The operator has left the area" in client.get(page).content.decode()

    answer = client.post(control, {"action": "left-area", "item": inspect.pk})

    assert answer.status_code == 302
    assert Interruption.objects.get(by_work_item=inspect).ended_at is not None
    assert "The operator has left the area" not in client.get(page).content.decode()
