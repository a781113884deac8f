"""The hot path: an operator's completion hands the step it enables to a free cobot in its own
transaction, a worker claims that lease in one statement, and each transaction runs a fixed
number of statements (counted here, so that a change cannot add one silently)."""

from __future__ import annotations

import datetime as dt
import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any

import pytest
from django.contrib.auth.models import User
from django.db import connection, connections, transaction
from django.test.utils import CaptureQueriesContext
from django.utils import timezone

from hrc.cases import dispatch, jobs, progress, services
from hrc.cases.choices import CaseStatus, IncidentKind, JobState, WorkItemState
from hrc.cases.dispatch import Task
from hrc.cases.models import Case, Incident, Job, WorkItem
from hrc.cobots.models import Cobot
from hrc.organisations.models import Organisation
from hrc.patterns.models import PatternVersion
from tests import factories

pytestmark = pytest.mark.django_db(transaction=True)


class Statements:
    """The SQL statements this connection sends (BEGIN and COMMIT are not among them)."""

    def __init__(self) -> None:
        self.sent: list[str] = []

    def __call__(self, execute: Callable[..., Any], sql: str, *args: Any) -> Any:
        self.sent.append(sql)
        return execute(sql, *args)


@contextmanager
def counted() -> Iterator[Statements]:
    statements = Statements()
    with connection.execute_wrapper(statements):
        yield statements


@contextmanager
def sent_tasks() -> Iterator[list[tuple[Task, tuple[Any, ...]]]]:
    """The Celery tasks sent after commit, kept instead of sent."""
    kept: list[tuple[Task, tuple[Any, ...]]] = []
    original = dispatch._send

    def keep(task: Task, args: tuple[Any, ...], countdown: float) -> None:
        kept.append((task, args))

    dispatch._send = keep
    try:
        yield kept
    finally:
        dispatch._send = original


@pytest.fixture
def version(organisation: Organisation, engineer: User) -> PatternVersion:
    return factories.make_version(organisation, published_by=engineer)


def _job(item: WorkItem) -> Job:
    return Job.objects.select_related("cobot").get(case_id=item.case_id)


def _leased(item: WorkItem, operator: User) -> jobs.Lease:
    """Completes the started task; the lease its step's message carries (the cobot was free)."""
    with sent_tasks() as sent:
        services.complete_work_item(item, user=operator)
    [(task, (message,))] = sent
    assert task == Task.RUN_LEASED_JOB
    return jobs.Lease.from_message(message)


def _queued(items: list[WorkItem], operator: User, cobot: Cobot) -> None:
    """Completes the started tasks while the cobot's cell is stopped, so that their steps wait
    in its queue, then lets the cell go (in its row only: no doorbell rings)."""
    Cobot.objects.filter(pk=cobot.pk).update(stopped_at=timezone.now())
    with sent_tasks():
        for item in items:
            services.complete_work_item(item, user=operator)
    Cobot.objects.filter(pk=cobot.pk).update(stopped_at=None)


def test_a_completion_leases_the_step_for_a_free_cobot_and_sends_the_lease_not_a_doorbell(
    version: PatternVersion, engineer: User, operator: User, cobot: Cobot
) -> None:
    item = factories.hand_over_started(version, started_by=engineer, operator=operator, cobot=cobot)
    with sent_tasks() as sent, counted() as statements:
        services.complete_work_item(item, user=operator)
    job = _job(item)
    assert (job.state, job.lease, job.held_by) == (JobState.RUNNING, 1, "")
    assert WorkItem.objects.get(pk=job.work_item_id).state == WorkItemState.RUNNING
    [(task, (message,))] = sent
    assert task == Task.RUN_LEASED_JOB
    assert (message["job"], message["lease"], message["cobot"]["name"]) == (job.pk, 1, cobot.name)
    assert message["command"] == job.command
    # The case and the item locked, its completion, the open items, the step's offer with its
    # job, the cobot's row, then the log, the step's start (which starts alone: no second read
    # of the open items), the lease and the case in one statement.
    assert len(statements.sent) == 6, statements.sent


def test_a_step_whose_command_cannot_be_made_is_offered_with_its_job_failed_and_an_incident(
    organisation: Organisation, engineer: User, operator: User, cobot: Cobot
) -> None:
    document = factories.valid_document()
    document["data"] = {"batch": "many"}
    document["processes"][0]["transitions"][1]["task"] = {"step": {"number": "=data.batch"}}
    version = factories.make_version(organisation, published_by=engineer, draft=document)
    item = factories.hand_over_started(version, started_by=engineer, operator=operator, cobot=cobot)
    with sent_tasks() as sent:
        services.complete_work_item(item, user=operator)
    assert sent == []  # nothing to lease, no doorbell
    job = _job(item)
    assert job.state == JobState.FAILED
    assert "not a whole number" in job.last_error
    step = WorkItem.objects.get(pk=job.work_item_id)
    assert (step.task, step.state) == ("tc1", WorkItemState.OFFERED)
    [incident] = Incident.objects.filter(case_id=item.case_id)
    assert (incident.kind, incident.work_item_id) == (IncidentKind.CASE_FAULT, step.pk)


@pytest.mark.parametrize("busy", ["queued", "stopped", "locked by a worker"])
def test_a_completion_queues_the_step_when_its_cobot_is_not_free(
    busy: str, version: PatternVersion, engineer: User, operator: User, cobot: Cobot
) -> None:
    ahead = factories.hand_over_started(
        version, started_by=engineer, operator=operator, cobot=cobot
    )
    item = factories.hand_over_started(version, started_by=engineer, operator=operator, cobot=cobot)
    if busy == "queued":
        services.complete_work_item(ahead, user=operator)  # its step leased: the cobot has work
    elif busy == "stopped":
        Cobot.objects.filter(pk=cobot.pk).update(stopped_at=timezone.now())
    with _cobot_locked(cobot.pk if busy == "locked by a worker" else None), sent_tasks() as sent:
        services.complete_work_item(item, user=operator)
    job = _job(item)
    assert (job.state, job.lease) == (JobState.QUEUED, 0)
    assert WorkItem.objects.get(pk=job.work_item_id).state == WorkItemState.OFFERED
    if busy == "queued":
        # Behind a step it saw running: that step's worker leases it next (jobs._drive).
        assert sent == []
    else:
        assert sent == [(Task.RUN_JOB, (job.pk,))]  # its doorbell, as before


@contextmanager
def _cobot_locked(cobot_id: int | None) -> Iterator[None]:
    """The cobot's row locked by another session (a worker leasing) while the block runs."""
    if cobot_id is None:
        yield
        return
    locked, release = threading.Event(), threading.Event()

    def hold() -> None:
        try:
            with transaction.atomic():
                Cobot.objects.select_for_update(no_key=True).get(pk=cobot_id)
                locked.set()
                release.wait(30)
        finally:
            connections.close_all()

    holder = threading.Thread(target=hold)
    holder.start()
    assert locked.wait(10)
    try:
        yield  # SKIP LOCKED: the completion does not wait for the worker
    finally:
        release.set()
        holder.join(10)


def test_a_worker_claims_a_leased_step_once_in_one_statement(
    version: PatternVersion, engineer: User, operator: User, cobot: Cobot
) -> None:
    item = factories.hand_over_started(version, started_by=engineer, operator=operator, cobot=cobot)
    lease = _leased(item, operator)
    with counted() as statements:
        assert jobs._claim(lease)
    assert len(statements.sent) == 1
    assert _job(item).held_by == progress.worker_name()
    assert not jobs._claim(lease)  # a duplicate of the message (the sweeper's) does nothing


def test_the_sweeper_sends_an_unclaimed_lease_again(
    version: PatternVersion, engineer: User, operator: User, cobot: Cobot, settings: Any
) -> None:
    settings.HRC_SWEEP_SECONDS = 0.0
    item = factories.hand_over_started(version, started_by=engineer, operator=operator, cobot=cobot)
    with sent_tasks() as lost:
        services.complete_work_item(item, user=operator)
    with sent_tasks() as sent:
        assert jobs.sweep()["unclaimed"] == 1
    [(message,)] = [args for task, args in sent if task == Task.RUN_LEASED_JOB]
    assert (message["job"], message["lease"]) == (lost[0][1][0]["job"], 1)
    assert jobs._claim(jobs.Lease.from_message(message))
    with sent_tasks():
        assert jobs.sweep()["unclaimed"] == 0  # claimed: nothing to send


def test_an_unclaimed_lease_is_sent_again_at_1_2_4_8_sweeps_of_age_not_at_every_sweep(
    version: PatternVersion, engineer: User, operator: User, cobot: Cobot, settings: Any
) -> None:
    settings.HRC_SWEEP_SECONDS = 2.0
    item = factories.hand_over_started(version, started_by=engineer, operator=operator, cobot=cobot)
    with sent_tasks():
        services.complete_work_item(item, user=operator)  # its message lost, or waiting its turn
    leased_at = _job(item).started_at
    assert leased_at is not None

    sent_at = [
        sweeps
        for sweeps in range(12)
        if jobs._unclaimed(leased_at + dt.timedelta(seconds=2.0 * sweeps + 0.1))
    ]

    assert sent_at == [1, 2, 4, 8]


def test_the_finish_runs_a_fixed_number_of_statements(
    version: PatternVersion, engineer: User, operator: User, cobot: Cobot
) -> None:
    item = factories.hand_over_started(version, started_by=engineer, operator=operator, cobot=cobot)
    lease = _leased(item, operator)
    assert jobs._claim(lease)
    with sent_tasks(), counted() as statements:
        jobs.finish_job(lease, {"outcome": "ran", "seconds": 0.0})
    assert Case.objects.get(pk=item.case_id).status == CaseStatus.COMPLETED
    # The case, the job and its item locked in one statement, the item's completion, the open
    # items, then the log, the job and the case in one statement; after the commit, whether
    # the cobot has a job queued (a worker that leases the next job itself asks nothing:
    # jobs._finish_and_lease_next).
    assert len(statements.sent) == 5, statements.sent


def test_a_doorbells_lease_runs_a_fixed_number_of_statements(
    version: PatternVersion, engineer: User, operator: User, cobot: Cobot
) -> None:
    item = factories.hand_over_started(version, started_by=engineer, operator=operator, cobot=cobot)
    _queued([item], operator, cobot)
    with counted() as statements:
        lease = jobs._lease_next("id = %s", cobot.pk)  # what a doorbell runs (run_next_job)
    assert lease is not None
    assert lease.job_id == _job(item).pk
    # The cobot's lock, its queue, the case, the job and its item locked in one statement, then
    # the log, the step's start (alone: nothing else to offer or withdraw), the lease and the
    # case in one statement.
    assert len(statements.sent) == 4, statements.sent


def _claimed_with_one_behind(
    version: PatternVersion, engineer: User, operator: User, cobot: Cobot
) -> tuple[WorkItem, jobs.Lease, WorkItem]:
    """Two operator tasks completed for one cobot: the first's step leased and claimed by this
    worker, the second's queued behind it. (first item, its lease, second item)"""
    first = factories.hand_over_started(
        version, started_by=engineer, operator=operator, cobot=cobot
    )
    second = factories.hand_over_started(
        version, started_by=engineer, operator=operator, cobot=cobot
    )
    lease = _leased(first, operator)
    with sent_tasks():
        services.complete_work_item(second, user=operator)  # queued behind the first
    assert jobs._claim(lease)
    return first, lease, second


def test_a_worker_done_with_a_step_leases_the_next_in_the_same_transaction(
    version: PatternVersion, engineer: User, operator: User, cobot: Cobot
) -> None:
    first, lease, second = _claimed_with_one_behind(version, engineer, operator, cobot)
    with sent_tasks() as rung, CaptureQueriesContext(connection) as captured:
        taken = jobs._finish_and_lease_next(
            lease, {"outcome": "ran", "seconds": 0.0}, accepted_at=None, hand_over=False
        )
    job = _job(second)
    assert taken is not None
    assert taken.job_id == job.pk
    assert (job.state, job.held_by) == (JobState.RUNNING, progress.worker_name())
    assert Case.objects.get(pk=first.case_id).status == CaseStatus.COMPLETED
    assert rung == []  # no doorbell, no message: this worker drives the next job
    sent = [query["sql"] for query in captured.captured_queries]
    control = [sql for sql in sent if sql.startswith(("BEGIN", "COMMIT", "SAVEPOINT"))]
    # finish_job's statements but the doorbell's question after the commit (4), then a
    # doorbell's lease (4), under one commit.
    assert control == ["BEGIN", "COMMIT"], control
    assert len(sent) - len(control) == 8, sent


def test_a_worker_done_with_a_step_leases_the_next_for_the_workers_when_told_to_hand_it_over(
    version: PatternVersion, engineer: User, operator: User, cobot: Cobot
) -> None:
    _, lease, second = _claimed_with_one_behind(version, engineer, operator, cobot)
    with sent_tasks() as rung:
        handed = jobs._finish_and_lease_next(
            lease, {"outcome": "ran", "seconds": 0.0}, accepted_at=None, hand_over=True
        )
    job = _job(second)
    assert handed is not None
    assert handed.job_id == job.pk
    assert (job.state, job.lease, job.held_by) == (JobState.RUNNING, 1, "")
    [(task, (message,))] = rung
    assert (task, message["job"], message["lease"]) == (Task.RUN_LEASED_JOB, job.pk, 1)


def test_a_lease_handed_to_the_workers_is_the_cobots_only_one(
    version: PatternVersion, engineer: User, operator: User, cobot: Cobot
) -> None:
    """The lease that hands the next job over ends the lease: the cobot has a job running."""
    _queued(
        [
            factories.hand_over_started(
                version, started_by=engineer, operator=operator, cobot=cobot
            )
            for _ in range(3)
        ],
        operator,
        cobot,
    )
    with sent_tasks() as rung:
        jobs._lease_next("id = %s", cobot.pk, hand_over=True)
    assert Job.objects.filter(cobot=cobot, state=JobState.RUNNING).count() == 1
    assert [task for task, _ in rung] == [Task.RUN_LEASED_JOB]
