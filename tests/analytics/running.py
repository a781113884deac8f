"""Cases for the analytics tests, run through the services and the worker's own functions.

A cobot step runs as a worker runs it, without the cobot: jobs.lease_next_job
(the task starts) then jobs.finish_job (the step's result, the task
completes). `pin` then sets the rows' timestamps to whole seconds after
START, so durations are exact; the event log keeps the real times.
"""

from __future__ import annotations

import datetime as dt

from django.contrib.auth.models import User

from hrc.cases import jobs, services
from hrc.cases.models import Case, Interruption, Job, WorkItem
from hrc.cobots.models import Cobot
from hrc.patterns.models import PatternVersion
from tests import factories

START = dt.datetime(2025, 3, 1, 8, 0, tzinfo=dt.UTC)


def at(seconds: float) -> dt.datetime:
    return START + dt.timedelta(seconds=seconds)


def mapping(operator: User, cobot: Cobot) -> dict[str, object]:
    return {"o": {"users": [operator.pk]}, "c": {"cobot": cobot.pk}}


def operator_does(case: Case, task: str, operator: User) -> WorkItem:
    item = factories.open_work_item(case, task)
    services.start_work_item(item, user=operator)
    services.complete_work_item(item, user=operator)
    return item


def run_hand_over(
    version: PatternVersion, engineer: User, operator: User, cobot: Cobot, *, finish: bool = True
) -> Case:
    """A hand-over case to its end (or with the cobot's step running when not `finish`)."""
    case = factories.make_case(version, started_by=engineer, actor_mapping=mapping(operator, cobot))
    operator_does(case, "to1", operator)
    lease = jobs.lease_next_job(cobot.pk)
    assert lease is not None
    if finish:
        jobs.finish_job(lease, {"outcome": "ran"})
    case.refresh_from_db()
    return case


def run_shared_space(version: PatternVersion, engineer: User, operator: User, cobot: Cobot) -> Case:
    """A shared-space case to its end: the operator inspects while the cobot picks, which
    interrupts the pick until the inspection is done."""
    case = factories.make_case(version, started_by=engineer, actor_mapping=mapping(operator, cobot))
    operator_does(case, "to1", operator)
    lease = jobs.lease_next_job(cobot.pk)  # the pick starts
    assert lease is not None
    operator_does(case, "to2", operator)  # starting the inspection interrupts the pick
    jobs.finish_job(lease, {"outcome": "ran"})
    case.refresh_from_db()
    return case


def pin(
    case: Case,
    *,
    started: float,
    ended: float | None,
    items: dict[str, tuple[float, float | None, float | None]],
    jobs_: dict[str, tuple[float, float | None, float | None]] | None = None,
) -> None:
    """Sets the case's and its rows' times (seconds after START): items and jobs by task,
    as (offered or queued, started, ended); a cobot item's start is when its step was accepted."""
    Case.objects.filter(pk=case.pk).update(
        started_at=at(started), ended_at=at(ended) if ended is not None else None
    )
    for task, (offered, began, done) in items.items():
        WorkItem.objects.filter(case=case, task=task).update(
            offered_at=at(offered), started_at=_at(began), ended_at=_at(done)
        )
        # A cobot task's item starts when its cobot accepted the step (analytics.selectors).
        Job.objects.filter(case=case, work_item__task=task, accepted_at__isnull=False).update(
            accepted_at=_at(began)
        )
    for task, (queued, began, done) in (jobs_ or {}).items():
        Job.objects.filter(case=case, work_item__task=task).update(
            queued_at=at(queued), started_at=_at(began), ended_at=_at(done)
        )
    case.refresh_from_db()


def pin_interruption(case: Case, started: float, ended: float | None) -> Interruption:
    interruption = Interruption.objects.get(case=case)
    Interruption.objects.filter(pk=interruption.pk).update(
        started_at=at(started), ended_at=_at(ended)
    )
    interruption.refresh_from_db()
    return interruption


def _at(seconds: float | None) -> dt.datetime | None:
    return at(seconds) if seconds is not None else None
