"""The cases' Celery tasks as a worker runs them."""

from __future__ import annotations

from typing import Any

import pytest

from hrc.cases import jobs, tasks


@pytest.mark.django_db
def test_sweeps_that_piled_up_in_the_broker_run_once_not_back_to_back(settings: Any) -> None:
    settings.HRC_SWEEP_SECONDS = 60.0
    jobs._last_sweep["at"] -= 3600  # this process last swept an hour ago
    first, second = tasks.sweep(), tasks.sweep()
    assert first.keys() >= {"expired", "rung", "timers"}
    assert second == {"skipped": 1}
    settings.HRC_SWEEP_SECONDS = 0.0  # a sweep per message, however close together
    assert "skipped" not in tasks.sweep()
