"""One cobot, one job at a time, even when two workers reach for the cobot at the same moment.

The second worker's lease waits on the cobot's row lock while the first
lease commits. Whatever the second reads about the cobot must be read after
it holds the lock: in PostgreSQL's READ COMMITTED a statement sees what was
committed when it began, so a busy check made in the statement that waited
for the lock would not see the first worker's job and would lease a second
one on the same cobot (two use-case cases sharing cobots did exactly that).
"""

from __future__ import annotations

import contextlib
import datetime as dt
import threading
from collections.abc import Callable
from typing import Any

import pytest
import redis
from django.contrib.auth.models import User
from django.db import connection, connections, transaction
from django.test.utils import CaptureQueriesContext
from django.utils import timezone

from hrc.cases import jobs, progress
from hrc.cases import services as case_services
from hrc.cases.choices import JobState, WorkItemState
from hrc.cases.models import Case, Job, WorkItem
from hrc.celery import app
from hrc.cobots.choices import CommandOutcome, ControlCommand
from hrc.cobots.models import Cobot, CobotCommand
from hrc.errors import Conflict
from hrc.organisations.choices import Role
from hrc.organisations.models import Organisation
from tests import factories
from tests.cases.patterns import PROGRAM
from tests.support.polling import until
from tests.support.workers import RedisProcess


def _one_cobot_task() -> dict[str, Any]:
    """The cobot picks (its job queued as the case starts) while the operator loads the cell."""
    transitions = [
        {"id": "split"},
        {
            "id": "tc1",
            "performer": "c",
            "label": "pick",
            "task": {"step": {"program": PROGRAM, "number": 3}},
        },
        {"id": "to1", "performer": "o", "label": "load the cell"},
        {"id": "join"},
    ]
    arcs = "p0>split split>p1 p1>tc1 tc1>p2 p2>join split>p3 p3>to1 to1>p4 p4>join join>p5"
    return {
        "format": "hrc-pattern/1",
        "name": "pick beside loading",
        "actors": [
            {"id": "c", "type": "cobot", "program": PROGRAM},
            {"id": "o", "type": "operator"},
        ],
        "processes": [
            {
                "id": "N",
                "workpiece": "w",
                "actors": ["c", "o"],
                "places": [{"id": f"p{i}", "tokens": 1 if i == 0 else 0} for i in range(6)],
                "transitions": transitions,
                "arcs": [arc.split(">") for arc in arcs.split()],
            }
        ],
        "constraints": [],
    }


def _two_jobs_queued_on_one_cobot(organisation: Organisation, engineer: User, operator: User) -> Cobot:  # fmt: skip
    """Two cases of _one_cobot_task on the same cobot: both jobs queued as the cases start."""
    return _jobs_queued_on_a_cobot(organisation, engineer, operator, "shared", 2)


def _jobs_queued_on_a_cobot(
    organisation: Organisation, engineer: User, operator: User, name: str, count: int
) -> Cobot:
    version = factories.make_version(organisation, published_by=engineer, draft=_one_cobot_task())
    cobot = factories.make_cobot(organisation, name=name)
    mapping = {"c": {"cobot": cobot.pk}, "o": {"users": [operator.pk]}}
    for _ in range(count):
        factories.make_case(version, started_by=engineer, actor_mapping=mapping)
    return cobot


def _waiting_for_a_lock() -> bool:
    with connection.cursor() as cursor:
        cursor.execute(
            "SELECT count(*) FROM pg_stat_activity "
            "WHERE datname = current_database() AND wait_event_type = 'Lock'"
        )
        return bool(cursor.fetchone()[0])


def _reach_while_held(
    hold: Callable[[], Any],
    reach: Callable[[], Any],
    waited: str,
    *,
    reach_commits: bool = False,
    meanwhile: Callable[[], None] = lambda: None,
) -> tuple[Any, Any]:
    """Runs `hold` in a transaction held open on a thread of its own, then `reach` in one on
    another thread (`reach_commits`: in none, as it commits its own), which must come to wait
    for a lock (`waited`: the failure if it never does); runs `meanwhile`, then lets `hold`
    commit. Returns what each returned."""
    held = threading.Event()
    release = threading.Event()
    results: dict[str, Any] = {}

    def run(name: str, call: Callable[[], Any], then: Callable[[], None], atomic: bool) -> None:
        try:
            with transaction.atomic() if atomic else contextlib.nullcontext():
                results[name] = call()
                then()
        finally:
            connections.close_all()

    def hold_open() -> None:
        held.set()
        release.wait(30)

    holder = threading.Thread(target=run, args=("hold", hold, hold_open, True))
    holder.start()
    assert held.wait(30)
    reacher = threading.Thread(target=run, args=("reach", reach, lambda: None, not reach_commits))
    reacher.start()
    until(_waiting_for_a_lock, 30, 0.01, waited)
    try:
        meanwhile()
    finally:
        release.set()
        holder.join(30)
        reacher.join(30)
    return results["hold"], results["reach"]


@pytest.mark.django_db(transaction=True)
def test_a_lease_that_waited_for_the_cobot_sees_the_job_leased_meanwhile(
    broker: RedisProcess, organisation: Organisation, engineer: User, operator: User
) -> None:
    # `broker`: the cases' doorbells go to a private redis-server that no worker reads.
    cobot = _two_jobs_queued_on_one_cobot(organisation, engineer, operator)
    assert Job.objects.filter(cobot=cobot, state=JobState.QUEUED).count() == 2

    first, second = _reach_while_held(
        lambda: jobs.lease_next_job(cobot.pk),  # the lease's own transaction, held open a moment
        lambda: jobs.lease_next_job(cobot.pk),
        "the second lease never waited for the cobot",
    )

    assert first is not None
    assert second is None  # the cobot is busy with the first job
    assert Job.objects.filter(cobot=cobot, state=JobState.RUNNING).count() == 1


@pytest.mark.django_db(transaction=True)
@pytest.mark.parametrize("locked", ["the cobot's row", "the next job's case"])
def test_a_finish_that_finds_a_lock_taken_commits_then_leases_the_next_job_once_it_is_free(
    broker: RedisProcess, organisation: Organisation, engineer: User, operator: User, locked: str
) -> None:
    # A worker done with a step leases the cobot's next job in the finish's transaction
    # (jobs._finish_and_lease_next), holding the finished case's lock: it must wait for no
    # other lock there, or two sessions could each wait for the other.
    cobot = _two_jobs_queued_on_one_cobot(organisation, engineer, operator)
    first = jobs.lease_next_job(cobot.pk)
    assert first is not None
    second = Job.objects.get(cobot=cobot, state=JobState.QUEUED)

    def hold() -> None:
        if locked == "the cobot's row":
            Cobot.objects.select_for_update(no_key=True).get(pk=cobot.pk)
        else:
            progress.lock_case(second.case_id)

    def finished_meanwhile() -> None:
        assert Job.objects.get(pk=first.job_id).state == JobState.SUCCEEDED
        assert Job.objects.get(pk=second.pk).state == JobState.QUEUED

    _, taken = _reach_while_held(
        hold,
        lambda: jobs._finish_and_lease_next(
            first, {"outcome": "ran", "seconds": 0}, accepted_at=None, hand_over=False
        ),
        "the lease after the finish never waited",
        reach_commits=True,
        meanwhile=finished_meanwhile,
    )
    assert taken is not None
    assert taken.job_id == second.pk
    assert Job.objects.get(pk=second.pk).state == JobState.RUNNING


@pytest.mark.django_db(transaction=True)
def test_a_finished_job_rings_for_the_cobots_next_job_only_when_one_is_queued(
    broker: RedisProcess, organisation: Organisation, engineer: User, operator: User
) -> None:
    cobot = _two_jobs_queued_on_one_cobot(organisation, engineer, operator)
    doorbells = redis.Redis.from_url(broker.url)
    queue = app.conf.task_default_queue
    assert doorbells.llen(queue) == 2  # each job's own, rung as its case started

    first = jobs.lease_next_job(cobot.pk)
    assert first is not None
    jobs.finish_job(first, {"outcome": "ran", "seconds": 0})
    assert doorbells.llen(queue) == 3  # the second job waits: ring for it

    second = jobs.lease_next_job(cobot.pk)
    assert second is not None
    jobs.finish_job(second, {"outcome": "ran", "seconds": 0})
    assert doorbells.llen(queue) == 3  # nothing left to run on the cobot: no doorbell
    assert set(Job.objects.filter(cobot=cobot).values_list("state", flat=True)) == {JobState.SUCCEEDED}  # fmt: skip


@pytest.mark.django_db(transaction=True)
def test_no_job_is_leased_while_a_persons_command_to_the_cobot_is_under_way(
    organisation: Organisation, engineer: User, operator: User
) -> None:
    cobot = _two_jobs_queued_on_one_cobot(organisation, engineer, operator)
    command = CobotCommand.objects.create(
        cobot=cobot, command=ControlCommand.LOAD_PROGRAM, requested_by=engineer
    )

    assert jobs.lease_next_job(cobot.pk) is None  # loading a program: no step meanwhile

    command.outcome, command.finished_at = CommandOutcome.OK, timezone.now()
    command.save()
    assert jobs.lease_next_job(cobot.pk) is not None


@pytest.mark.django_db(transaction=True)
def test_a_cancelled_cases_job_whose_lease_expires_ends_with_the_case_not_back_in_the_queue(
    organisation: Organisation, engineer: User, operator: User
) -> None:
    cobot = _two_jobs_queued_on_one_cobot(organisation, engineer, operator)
    lease = jobs.lease_next_job(cobot.pk)
    assert lease is not None
    case_services.cancel_case(Case.objects.get(pk=lease.case_id), by=engineer)
    # The worker that held the step died: its lease runs out.
    Job.objects.filter(pk=lease.job_id).update(lease_expires_at=timezone.now())

    jobs.sweep()

    job = Job.objects.get(pk=lease.job_id)
    assert job.state == JobState.CANCELLED
    assert job.ended_at is not None


@pytest.mark.django_db(transaction=True)
@pytest.mark.parametrize("queued", [3, 30])
def test_the_sweeper_rings_each_cobots_first_due_job_in_one_read_however_long_the_queue(
    broker: RedisProcess, organisation: Organisation, engineer: User, operator: User, queued: int
) -> None:
    # `broker`: the doorbells go to a private redis-server that no worker reads.
    busy = _jobs_queued_on_a_cobot(organisation, engineer, operator, "busy", 2)
    waiting = _jobs_queued_on_a_cobot(organisation, engineer, operator, "waiting", queued)
    assert jobs.lease_next_job(busy.pk) is not None  # busy runs a step: no doorbell for it
    backing_off, first_due, *_ = Job.objects.filter(cobot=waiting).order_by("queued_at", "id")
    Job.objects.filter(pk=backing_off.pk).update(  # its last try failed: not due yet
        next_try_at=timezone.now() + dt.timedelta(minutes=1)
    )

    with CaptureQueriesContext(connection) as queries:
        assert jobs._first_due_per_cobot(timezone.now()) == [first_due.pk]

    assert len(queries) == 1


@pytest.mark.django_db(transaction=True)
def test_a_lock_that_waited_for_the_case_reads_its_job_and_work_item_as_left_by_the_holder(
    broker: RedisProcess, organisation: Organisation, engineer: User, operator: User
) -> None:
    # One statement locks the case, the job and its work item (jobs.lock_case_and_job): begun
    # before the wait, it must still read what the holder of the case's lock committed.
    cobot = _jobs_queued_on_a_cobot(organisation, engineer, operator, "alone", 1)
    job = Job.objects.get(cobot=cobot)

    def cancel_meanwhile() -> None:
        progress.lock_case(job.case_id)
        WorkItem.objects.filter(pk=job.work_item_id).update(state=WorkItemState.CANCELLED)
        Job.objects.filter(pk=job.pk).update(waiting_for="cancelled meanwhile")

    _, (_, read) = _reach_while_held(
        cancel_meanwhile,
        lambda: jobs.lock_case_and_job(job.case_id, job.pk),
        "the lock never waited for the case",
    )
    assert read.waiting_for == "cancelled meanwhile"
    assert read.work_item.state == WorkItemState.CANCELLED


@pytest.mark.django_db(transaction=True)
def test_an_operator_action_that_waited_for_the_case_reads_its_work_item_as_left_by_the_holder(
    broker: RedisProcess, organisation: Organisation, engineer: User, operator: User
) -> None:
    # One statement locks the case and the operator's work item (progress.lock_operator_item):
    # begun before the wait, it must still read what the holder of the case's lock committed.
    cobot = factories.make_cobot(organisation, name="handed")
    version = factories.make_version(organisation, published_by=engineer)
    item = factories.hand_over_started(version, started_by=engineer, operator=operator, cobot=cobot)
    other = factories.make_member(organisation, Role.OPERATOR)

    def reassign_meanwhile() -> None:
        progress.lock_case(item.case_id)
        WorkItem.objects.filter(pk=item.pk).update(claimed_by=other)

    def complete() -> str:
        try:
            case_services.complete_work_item(item.pk, user=operator)
        except Conflict as refused:
            return str(refused)
        return "completed"

    _, answer = _reach_while_held(
        reassign_meanwhile, complete, "the completion never waited for the case"
    )
    assert answer == f"{item.label} is being done by someone else."
    assert WorkItem.objects.get(pk=item.pk).state == WorkItemState.RUNNING
