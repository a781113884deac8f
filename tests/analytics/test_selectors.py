"""What analytics read from real runs: a cobot's work is the time it ran a step, on a real
simulated gateway through the worker's own job path."""

from __future__ import annotations

import time
from pathlib import Path

import pytest
from django.utils import timezone

from hrc.analytics.selectors import version_analytics
from hrc.cases import services
from hrc.cases.choices import CaseStatus
from hrc.cases.models import Case, Incident, Job
from hrc.cases.simulation import Simulation
from tests.cases.patterns import cobot_chain
from tests.support.polling import until

pytestmark = pytest.mark.django_db(transaction=True)

STUCK = 1.5  # seconds the step waits for a person to power the cobot on


def test_a_step_stuck_on_a_powered_off_cobot_is_not_counted_as_its_work(tmp_path: Path) -> None:
    with Simulation(cobot_chain(steps=1), tmp_path, time_scale=0.0, power_on=False) as run:
        with run.running():
            [case_id] = run.start_cases(1)
            incident = until(lambda: Incident.objects.filter(case_id=case_id).first(), 30)
            time.sleep(STUCK)
            run.cobot("c").call("PowerOn", timeout=30)  # the person at the pendant
            services.resolve_incident(incident, by=run.users["o"], resolution="retry")
            assert run.wait([case_id], timeout=60)
        figures = version_analytics(run.version, now=timezone.now())

    assert Case.objects.get(pk=case_id).status == CaseStatus.COMPLETED
    job = Job.objects.get(case_id=case_id)
    assert job.started_at is not None
    assert job.ended_at is not None
    assert (job.ended_at - job.started_at).total_seconds() > STUCK  # leased, stuck, then ran
    [cobot] = figures.cobots
    assert cobot.busy_seconds < STUCK / 2
    [step] = [task for task in figures.tasks if task.task == "tc1"]
    assert step.work.max is not None
    assert step.work.max < STUCK / 2
    assert step.wait.max is not None
    assert step.wait.max > STUCK
