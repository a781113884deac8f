"""The embedded set-up (no Redis): jobs on threads of the server, and its own sweeper."""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor
from typing import Any

import pytest
from django.contrib.auth.models import User

from hrc.cases import dispatch, services
from hrc.cases.choices import JobState
from hrc.cases.models import Job
from hrc.organisations.models import Organisation
from tests import factories
from tests.cases.patterns import cobot_chain
from tests.support.polling import until
from tests.support.workers import RedisProcess

pytestmark = pytest.mark.django_db(transaction=True)


def test_the_embedded_sweeper_finds_a_job_whose_doorbell_was_lost(
    broker: RedisProcess,
    settings: Any,  # pytest-django's settings fixture: restored after the test
    organisation: Organisation,
    engineer: User,
    operator: User,
) -> None:
    # A cobot nobody answers for: the job's first run fails fast and says so.
    cobot = factories.make_cobot(organisation, endpoint="opc.tcp://127.0.0.1:1")
    version = factories.make_version(
        organisation, published_by=engineer, draft=cobot_chain(steps=1)
    )
    case = factories.make_case(
        version, started_by=engineer,
        actor_mapping={"o": {"users": [operator.pk]}, "c": {"cobot": cobot.pk}},
    )  # fmt: skip
    item = factories.open_work_item(case, "to1")
    services.start_work_item(item, user=operator)
    services.complete_work_item(
        item, user=operator, data={}
    )  # the doorbell goes to a broker no worker reads
    job = Job.objects.get(case=case)

    settings.HRC_INLINE_TASKS, settings.HRC_SWEEP_SECONDS = True, 0.1
    dispatch.start_embedded_sweeper()

    until(lambda: _last_error(job), timeout=15, interval=0.05)
    assert cobot.name in job.last_error
    assert job.state in (JobState.QUEUED, JobState.FAILED)  # retried with back-off, or an incident


def _last_error(job: Job) -> str:
    job.refresh_from_db()
    return job.last_error


def test_a_task_sent_to_the_embedded_pool_as_the_process_exits_is_left_to_the_sweeper() -> None:
    # The sweeper's daemon thread can wake after the interpreter shut the pool down.
    ran: list[int] = []
    pool = ThreadPoolExecutor(max_workers=1)
    pool.shutdown()
    dispatch._submit_inline(pool, ran.append, (1,), 0)  # no RuntimeError, no traceback
    assert ran == []
