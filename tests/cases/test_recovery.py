"""Nothing lost, nothing done twice: real workers, a real broker and simulated cobots under faults.

Each trial starts cases of a chain of cobot picks, waits until a step is
running on the cobot, then does the harm: SIGKILL the worker that holds the
step, restart the broker, or SIGKILL and restart the cobot's gateway. Every
case must still complete, and the simulator (not our database) must have
run each step exactly once: one execution per job, each token once.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from pathlib import Path

import pytest

from hrc.cases.choices import CaseStatus, JobState
from hrc.cases.models import Case, Incident, Job
from hrc.cases.simulation import Simulation
from tests.cases.patterns import cobot_chain
from tests.support.polling import until
from tests.support.workers import RedisProcess, WorkerProcess

TRIALS = 3
CASES_PER_TRIAL = 2
# A pick lasts 2 s of robot time: 0.5 s here, long enough to strike in the middle of one.
TIME_SCALE = 0.25


def _running_step(timeout: float = 30.0) -> Job:
    """A step that has been on the cobot for a moment: sent, and not yet acknowledged."""
    job: Job = until(_held_running_job, timeout, 0.01, "no step started running")
    time.sleep(0.15)  # into the step (it takes ~0.5 s)
    return job


def _held_running_job() -> Job | None:
    job = Job.objects.filter(state=JobState.RUNNING).first()
    return job if job is not None and job.held_by else None


def _kill_holder(
    job: Job, workers: list[WorkerProcess], start: Callable[..., WorkerProcess]
) -> None:
    pid = int(job.held_by.rsplit(":", 1)[1])
    holder = next(w for w in workers if pid in w.pids())
    holder.kill()
    workers.remove(holder)
    workers.append(start(beat=holder.beat))


@pytest.mark.django_db(transaction=True)
@pytest.mark.parametrize("fault", ["worker-killed", "broker-restarted", "gateway-restarted"])
def test_every_case_completes_and_every_step_runs_once_despite(
    fault: str, start_worker: Callable[..., WorkerProcess], broker: RedisProcess, tmp_path: Path
) -> None:
    workers = [start_worker(beat=True), start_worker()]
    with Simulation(cobot_chain(), tmp_path, time_scale=TIME_SCALE, inline=False) as simulation:
        cases: list[int] = []
        with simulation.running():
            for _ in range(TRIALS):
                trial = simulation.start_cases(CASES_PER_TRIAL)
                cases += trial
                job = _running_step()
                if fault == "worker-killed":
                    _kill_holder(job, workers, start_worker)
                elif fault == "broker-restarted":
                    broker.restart(down_for=1.0)
                else:
                    gateway = simulation.gateways["c"]
                    gateway.kill()
                    time.sleep(0.5)
                    gateway.start()
                assert simulation.wait(trial, timeout=120), "the trial's cases did not end in time"
        executions, tokens = simulation.executed_steps("c")

    incidents = list(Incident.objects.filter(case__in=cases).values_list("message", flat=True))
    assert incidents == []
    assert set(Case.objects.filter(pk__in=cases).values_list("status", flat=True)) == {
        CaseStatus.COMPLETED
    }
    steps = Job.objects.filter(case__in=cases)
    assert set(steps.values_list("state", flat=True)) == {JobState.SUCCEEDED}
    assert executions == steps.count() == TRIALS * CASES_PER_TRIAL * 4
    # Entries read "<step id>.<attempt> step=3 program=…".
    assert sorted(entry.split()[0] for entry in tokens) == sorted(
        f"{job.pk}.{job.attempt}" for job in steps
    )
