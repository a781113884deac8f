"""A func hold reserves its cobot: once a supporting cobot's step has run, its task is held until
the supported task completes, and meanwhile no other case's job may move the cobot.

The lease, the sweeper and the job's reason to wait on the job path without a gateway (a step's
result is handed to finish_job as a worker would), then two cases on a simulated gateway, whose
jobs run on this process's threads with no sweeper: only the hold's doorbell can start the
waiting case's step.
"""

from __future__ import annotations

import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any

import pytest
import redis
from django.contrib.auth.models import User

from hrc.cases import dispatch, jobs, services
from hrc.cases.choices import CaseStatus, JobState, WorkItemState
from hrc.cases.models import Case, Job, WorkItem
from hrc.cases.selectors import cobot_in_use
from hrc.cases.simulation import Simulation
from hrc.celery import app
from hrc.cobots.models import Cobot
from hrc.organisations.models import Organisation
from tests import factories
from tests.cases.patterns import PICK, func_hold
from tests.support.polling import until
from tests.support.workers import RedisProcess

pytestmark = pytest.mark.django_db(transaction=True)

RAN = {"outcome": "ran", "seconds": 0.5}


def _two_cases_on_one_cobot(
    organisation: Organisation, engineer: User, operator: User, *, supported_by_cobot: bool = False
) -> tuple[Cobot, Case, Case]:
    """Two cases of func_hold sharing one cobot; the first's job is first in its queue."""
    version = factories.make_version(
        organisation, published_by=engineer, draft=func_hold(supported_by_cobot)
    )
    cobot = factories.make_cobot(organisation, name="shared")
    mapping: dict[str, Any] = {"c": {"cobot": cobot.pk}}
    mapping |= (
        {"c2": {"cobot": cobot.pk}} if supported_by_cobot else {"o": {"users": [operator.pk]}}
    )
    first, second = (
        factories.make_case(version, started_by=engineer, actor_mapping=mapping) for _ in range(2)
    )
    return cobot, first, second


def _hold(cobot: Cobot, case: Case) -> None:
    """The case's cobot step runs and succeeds: its task is held by the func constraint."""
    lease = jobs.lease_next_job(cobot.pk)
    assert lease is not None
    assert lease.case_id == case.pk
    jobs.finish_job(lease, RAN)
    held = factories.open_work_item(case, "tc1")
    assert held.state == WorkItemState.RUNNING
    assert held.job.state == JobState.SUCCEEDED


def _doorbells(broker: RedisProcess) -> int:
    return int(redis.Redis.from_url(broker.url).llen(app.conf.task_default_queue))


def test_another_case_waits_while_the_cobot_holds_and_goes_when_the_supported_task_completes(
    broker: RedisProcess, organisation: Organisation, engineer: User, operator: User
) -> None:
    cobot, holder, waiter = _two_cases_on_one_cobot(organisation, engineer, operator)
    _hold(cobot, holder)
    reason = f"holding for: screw the part, case {holder.pk}"

    assert jobs.lease_next_job(cobot.pk) is None  # nothing runs, yet the cobot is reserved
    waiting = Job.objects.get(case=waiter)
    assert (waiting.state, waiting.waiting_for) == (JobState.QUEUED, reason)
    assert cobot_in_use(cobot.pk) == reason
    assert jobs.sweep()["rung"] == 0  # the sweeper leaves it be too

    # The operator screws the part: the hold ends, and the waiting case's doorbell rings.
    rung = _doorbells(broker)
    screw = factories.open_work_item(holder, "to1")
    services.start_work_item(screw, user=operator)
    assert _doorbells(broker) == rung
    services.complete_work_item(screw, user=operator)
    assert _doorbells(broker) == rung + 1
    holder.refresh_from_db()
    assert holder.status == CaseStatus.COMPLETED

    lease = jobs.lease_next_job(cobot.pk)
    assert lease is not None
    assert lease.case_id == waiter.pk
    assert cobot_in_use(cobot.pk) == f"step {PICK} of hold the part, case {waiter.pk} is running"


def test_cancelling_the_holding_case_frees_the_cobot_at_once(
    broker: RedisProcess, organisation: Organisation, engineer: User, operator: User
) -> None:
    cobot, holder, waiter = _two_cases_on_one_cobot(organisation, engineer, operator)
    _hold(cobot, holder)
    assert jobs.lease_next_job(cobot.pk) is None

    rung = _doorbells(broker)
    services.cancel_case(holder, by=engineer, reason="the part fell")

    assert _doorbells(broker) == rung + 1
    assert cobot_in_use(cobot.pk) == ""
    lease = jobs.lease_next_job(cobot.pk)
    assert lease is not None
    assert lease.case_id == waiter.pk


def test_the_holding_cases_own_job_may_use_the_cobot_it_holds(
    broker: RedisProcess, organisation: Organisation, engineer: User, operator: User
) -> None:
    # Both cobot actors are one cobot, which does the supported task itself: waiting for the
    # hold would wait for ever.
    cobot, holder, waiter = _two_cases_on_one_cobot(
        organisation, engineer, operator, supported_by_cobot=True
    )
    _hold(cobot, holder)  # the holder's tc2 is queued behind the waiter's tc1

    lease = jobs.lease_next_job(cobot.pk)
    assert lease is not None
    assert Job.objects.get(pk=lease.job_id).work_item.task == "tc2"
    assert lease.case_id == holder.pk
    jobs.finish_job(lease, RAN)

    holder.refresh_from_db()
    assert holder.status == CaseStatus.COMPLETED
    assert jobs.lease_next_job(cobot.pk).case_id == waiter.pk  # type: ignore[union-attr]


def test_a_cobot_nobody_uses_is_not_in_use(organisation: Organisation) -> None:
    assert cobot_in_use(factories.make_cobot(organisation).pk) == ""


def _screw(case_id: int, user: User) -> None:
    screw = until(lambda: _offered(case_id, "to1"))
    services.start_work_item(screw, user=user)
    services.complete_work_item(screw, user=user)


def _offered(case_id: int, task: str) -> Any:
    return WorkItem.objects.filter(case_id=case_id, task=task, state=WorkItemState.OFFERED).first()


def test_on_a_gateway_the_other_cases_step_starts_once_the_hold_ends_and_not_before(
    tmp_path: Path,
) -> None:
    with (
        Simulation(func_hold(), tmp_path, time_scale=0.05, inline=False) as simulation,
        ThreadPoolExecutor(max_workers=2) as pool,
        dispatch.run_inline(pool),  # the doorbells run jobs on these threads; no sweeper
    ):
        holder, waiter = simulation.start_cases(2)
        until(lambda: Job.objects.filter(case_id=holder, state=JobState.SUCCEEDED).exists())
        time.sleep(1.0)  # ample for a doorbell to start the other case's step (a pick is 0.1 s)

        waiting = Job.objects.get(case_id=waiter)
        assert waiting.state == JobState.QUEUED
        assert waiting.waiting_for == f"holding for: screw the part, case {holder}"
        assert simulation.executed_steps("c")[0] == 1  # the cobot has not moved since

        _screw(holder, simulation.users["o"])
        released = time.monotonic()
        until(lambda: Job.objects.filter(pk=waiting.pk, started_at__isnull=False).exists())
        latency = time.monotonic() - released
        _screw(waiter, simulation.users["o"])
        until(lambda: Case.objects.filter(pk=waiter, status=CaseStatus.COMPLETED).exists())
        executions, _ = simulation.executed_steps("c")

    assert latency < 2.0, f"the waiting step started {latency:.2f} s after the hold ended"
    assert executions == 2
    assert Case.objects.get(pk=holder).status == CaseStatus.COMPLETED
