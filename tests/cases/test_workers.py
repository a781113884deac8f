"""Real Celery workers as cases use them: the app's hooks around each task (hrc/celery.py)."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest

from hrc.cases.choices import CaseStatus
from hrc.cases.models import Case
from hrc.cases.simulation import Simulation
from tests.cases.patterns import cobot_chain
from tests.postgres import sessions_opened
from tests.support.workers import WorkerProcess


@pytest.mark.django_db(transaction=True)
def test_a_worker_keeps_its_database_session_from_one_step_to_the_next(
    start_worker: Callable[..., WorkerProcess], tmp_path: Path
) -> None:
    # Celery's Django fix-up would close it around every task: a session per task,
    # and three cases of two steps take at least six tasks.
    start_worker()
    simulation = Simulation(cobot_chain(steps=2), tmp_path, time_scale=0.0, inline=False)
    with simulation, simulation.running():
        first = simulation.start_cases(1)
        assert simulation.wait(first, timeout=60)
        before = sessions_opened()
        more = simulation.start_cases(3)
        assert simulation.wait(more, timeout=60)
        opened = sessions_opened() - before
    assert opened <= 1  # the worker's own first one may be counted late
    statuses = set(Case.objects.filter(pk__in=first + more).values_list("status", flat=True))
    assert statuses == {CaseStatus.COMPLETED}
