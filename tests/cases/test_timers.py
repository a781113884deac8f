"""Timer transitions at run time: armed while enabled, rung once when due (by a real worker, the
embedded pool, or the sweeper when the doorbell was lost), never twice, never early."""

from __future__ import annotations

import datetime as dt
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor

import pytest
from django.contrib.auth.models import User
from django.db import connections
from django.test import Client
from django.urls import reverse
from django.utils import timezone
from pytest_django import DjangoCaptureOnCommitCallbacks

from hrc.cases import dispatch, services, timers
from hrc.cases.choices import CaseStatus, EventType, TimerState, WorkItemState
from hrc.cases.dispatch import Task
from hrc.cases.models import Case, CaseEvent, CaseTimer
from hrc.organisations.models import Organisation
from hrc.patterns.models import PatternVersion
from tests import factories
from tests.cases import patterns
from tests.support.polling import until
from tests.support.workers import WorkerProcess

FIVE_MINUTES = 300.0


@pytest.fixture
def deadline_version(organisation: Organisation, engineer: User) -> PatternVersion:
    """The inspection under a five-minute deadline (PT5M)."""
    return factories.make_version(
        organisation, published_by=engineer, draft=patterns.inspection_with_deadline()
    )


def _start(version: PatternVersion, operator: User, timer_scale: float = 1.0) -> Case:
    return services.start_case(
        version, started_by=operator, actor_mapping={"o": {"users": [operator.pk]}},
        timer_scale=timer_scale,
    )  # fmt: skip


def _timer(case: Case) -> CaseTimer:
    return CaseTimer.objects.get(case=case, transition="late")


def _fired(case: Case) -> list[str]:
    return list(
        CaseEvent.objects.filter(case=case, type=EventType.TIMER_FIRED).values_list(
            "task", flat=True
        )
    )


@pytest.mark.django_db
def test_a_timer_is_armed_for_its_duration_times_the_case_timer_scale(
    deadline_version: PatternVersion, operator: User
) -> None:
    before = timezone.now()
    plant = _timer(_start(deadline_version, operator))
    simulated = _timer(_start(deadline_version, operator, timer_scale=0.01))

    assert plant.state == simulated.state == TimerState.ARMED
    waits = (plant.due_at - before).total_seconds()
    assert FIVE_MINUTES <= waits < FIVE_MINUTES + 5
    assert 3 <= (simulated.due_at - before).total_seconds() < 8


@pytest.mark.django_db
def test_a_task_done_in_time_disarms_the_timer(
    deadline_version: PatternVersion, operator: User
) -> None:
    case = _start(deadline_version, operator, timer_scale=0)
    item = factories.open_work_item(case, "to1")
    services.start_work_item(item, user=operator)
    services.complete_work_item(item, user=operator)

    timer = _timer(case)
    assert timer.state == TimerState.DISARMED
    assert timers.ring_timer(timer.pk) is False
    case.refresh_from_db()
    assert case.status == CaseStatus.COMPLETED
    assert _fired(case) == []


@pytest.mark.django_db
def test_arming_and_disarming_a_timer_are_case_events_naming_it(
    deadline_version: PatternVersion, operator: User
) -> None:
    case = _start(deadline_version, operator, timer_scale=0)
    item = factories.open_work_item(case, "to1")
    services.start_work_item(item, user=operator)
    services.complete_work_item(item, user=operator)

    timer = _timer(case)
    events = CaseEvent.objects.filter(case=case, type__startswith="timer-").order_by("seq")
    said = {"transition": "late", "label": "inspection late", "due_at": timer.due_at.isoformat()}
    assert [(event.type, event.task, event.detail) for event in events] == [
        (EventType.TIMER_ARMED, "late", said),
        (EventType.TIMER_DISARMED, "late", said),
    ]


@pytest.mark.django_db
def test_a_due_timer_fires_once_and_the_case_goes_on(
    deadline_version: PatternVersion, operator: User
) -> None:
    case = _start(deadline_version, operator, timer_scale=0)
    timer = _timer(case)

    assert timers.ring_timer(timer.pk) is True
    assert timers.ring_timer(timer.pk) is False  # a redelivered doorbell

    timer.refresh_from_db()
    assert timer.state == TimerState.FIRED
    assert timer.ended_at is not None
    assert _fired(case) == ["late"]
    fired = CaseEvent.objects.get(case=case, type=EventType.TIMER_FIRED)
    assert fired.detail["due_at"] == timer.due_at.isoformat()
    assert fired.detail["transition"] == "late"
    # The inspection was only offered: its input emptied, it is withdrawn; rework is offered.
    assert case.work_items.get(task="to1").state == WorkItemState.WITHDRAWN
    rework = factories.open_work_item(case, "to_rework")
    services.start_work_item(rework, user=operator)
    services.complete_work_item(rework, user=operator)
    case.refresh_from_db()
    assert case.status == CaseStatus.COMPLETED
    assert not CaseTimer.objects.filter(case=case, state=TimerState.ARMED).exists()


@pytest.mark.django_db
def test_an_early_doorbell_fires_nothing_and_rings_again_when_due(
    deadline_version: PatternVersion,
    operator: User,
    django_capture_on_commit_callbacks: DjangoCaptureOnCommitCallbacks,
) -> None:
    case = _start(deadline_version, operator)
    timer = _timer(case)

    with django_capture_on_commit_callbacks() as rings:
        assert timers.ring_timer(timer.pk) is False

    assert len(rings) == 1  # the doorbell again, for the due time
    timer.refresh_from_db()
    assert timer.state == TimerState.ARMED
    assert _fired(case) == []


@pytest.mark.django_db
def test_a_suspended_case_timer_waits_until_the_case_resumes(
    deadline_version: PatternVersion, operator: User
) -> None:
    case = _start(deadline_version, operator, timer_scale=0)
    services.suspend_case(case, by=operator)

    assert timers.ring_timer(_timer(case).pk) is False

    services.resume_case(case, by=operator)
    assert timers.ring_timer(_timer(case).pk) is True
    assert _fired(case) == ["late"]


@pytest.mark.django_db
def test_a_cancelled_case_disarms_its_timers(
    deadline_version: PatternVersion, operator: User
) -> None:
    case = _start(deadline_version, operator, timer_scale=0)
    services.cancel_case(case, by=operator)

    timer = _timer(case)
    assert timer.state == TimerState.DISARMED
    assert timers.ring_timer(timer.pk) is False


@pytest.mark.django_db
def test_the_case_page_shows_when_a_timer_rings(
    deadline_version: PatternVersion, operator: User, engineer: User
) -> None:
    case = _start(deadline_version, operator)
    due = timezone.localtime(_timer(case).due_at).strftime("%H:%M:%S")
    client = Client()
    client.force_login(engineer)

    page = client.get(reverse("cases:case-detail", args=[case.pk])).content.decode()

    assert "waiting until <time datetime=" in page
    assert f">{due}</time> (inspection late)" in page


@pytest.mark.django_db(transaction=True)
def test_a_real_worker_rings_the_timer_when_it_is_due(
    deadline_version: PatternVersion,
    operator: User,
    start_worker: Callable[..., WorkerProcess],
) -> None:
    start_worker()
    case = _start(deadline_version, operator, timer_scale=1.5 / FIVE_MINUTES)  # due in 1.5 s
    timer = _timer(case)

    until(lambda: _fired(case), timeout=30, message="the timer never rang")

    timer.refresh_from_db()
    assert timer.ended_at is not None
    assert timer.ended_at >= timer.due_at
    assert timer.ended_at - timer.armed_at >= dt.timedelta(seconds=1.4)  # not a moment early
    assert factories.open_work_item(case, "to_rework")


@pytest.mark.django_db(transaction=True)
def test_the_sweeper_rings_a_timer_whose_doorbell_was_lost(
    deadline_version: PatternVersion,
    operator: User,
    start_worker: Callable[..., WorkerProcess],
) -> None:
    case = _start(deadline_version, operator)  # its doorbell rings in five minutes
    # The time has come, and the broker lost the doorbell that would have rung.
    CaseTimer.objects.filter(case=case).update(due_at=timezone.now() - dt.timedelta(seconds=5))
    start_worker(beat=True)

    until(lambda: _fired(case), timeout=30, message="the sweeper never rang the timer")
    assert _timer(case).state == TimerState.FIRED


@pytest.mark.django_db(transaction=True)
def test_inline_runs_ring_timers_on_their_pool(
    deadline_version: PatternVersion, operator: User
) -> None:
    pool = ThreadPoolExecutor(max_workers=2)
    try:
        with dispatch.run_inline(pool):
            case = _start(deadline_version, operator, timer_scale=0.3 / FIVE_MINUTES)
            until(lambda: _fired(case), timeout=10, message="the timer never rang inline")
    finally:
        pool.shutdown(wait=True)
        connections.close_all()
    assert factories.open_work_item(case, "to_rework")


@pytest.mark.django_db
def test_a_case_waiting_only_for_a_timer_runs_on_until_it_rings(
    organisation: Organisation, engineer: User, operator: User
) -> None:
    version = factories.make_version(
        organisation, published_by=engineer, draft=patterns.cool_down_then_inspect()
    )
    case = _start(version, operator, timer_scale=0)

    assert case.status == CaseStatus.RUNNING  # nothing to offer is no fault while a timer waits
    assert not case.work_items.exists()
    assert timers.ring_timer(CaseTimer.objects.get(case=case, transition="cool_down").pk)
    assert factories.open_work_item(case, "to1")


@pytest.mark.django_db
def test_the_admin_lists_timers_and_changes_none(
    deadline_version: PatternVersion, operator: User, staff_client: Client
) -> None:
    case = _start(deadline_version, operator)
    timer = _timer(case)

    listing = staff_client.get(reverse("admin:cases_casetimer_changelist"))
    assert listing.status_code == 200
    assert "late" in listing.content.decode()
    assert staff_client.get(reverse("admin:cases_casetimer_add")).status_code == 403
    delete = reverse("admin:cases_casetimer_delete", args=[timer.pk])
    assert staff_client.post(delete, {"post": "yes"}).status_code == 403
    assert _timer(case).state == TimerState.ARMED


@pytest.mark.django_db
def test_only_a_timer_due_soon_gets_a_doorbell_a_later_one_is_the_sweeper_s(
    organisation: Organisation,
    engineer: User,
    operator: User,
    monkeypatch: pytest.MonkeyPatch,
    django_capture_on_commit_callbacks: DjangoCaptureOnCommitCallbacks,
) -> None:
    """Redis hands an unacknowledged message out again every hour: a doorbell held for a day
    would come back 24 times."""
    sent: list[tuple[str, tuple[object, ...], float]] = []

    def record(task: str, args: tuple[object, ...], countdown: float) -> None:
        sent.append((task, args, countdown))

    monkeypatch.setattr(dispatch, "_send", record)
    soon, later = (
        factories.make_version(
            organisation, published_by=engineer, draft=patterns.inspection_with_deadline(timer)
        )
        for timer in ("PT5M", "P1D")
    )
    with django_capture_on_commit_callbacks(execute=True):
        soon_case, later_case = _start(soon, operator), _start(later, operator)

    [(args, countdown)] = [(a, c) for task, a, c in sent if task == Task.RING_TIMER]
    assert args == (_timer(soon_case).pk,)
    assert FIVE_MINUTES - 5 < countdown <= FIVE_MINUTES

    CaseTimer.objects.filter(case=later_case).update(
        due_at=timezone.now() - dt.timedelta(seconds=5)
    )
    with django_capture_on_commit_callbacks(execute=True):
        assert timers.sweep_timers() == 1
    assert sent[-1] == (Task.RING_TIMER, (_timer(later_case).pk,), 0)
