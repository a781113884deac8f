"""Checks run in the engine's worker processes, off the server's threads."""

from __future__ import annotations

import os
import signal

from hrc.engine.check import report_of
from hrc.patterns import checking
from tests import factories


def worker_pids() -> list[int]:
    processes = checking._workers()._processes.values()  # concurrent.futures keeps them here
    return [process.pid for process in processes if process.pid is not None]


def test_a_check_runs_in_an_engine_worker_and_answers_as_the_engine_does() -> None:
    document = factories.valid_document()

    report = checking.checked(document, checking.interactive_budget())

    assert report == report_of(document, checking.interactive_budget())
    assert report["valid"] is True
    assert worker_pids()
    assert os.getpid() not in worker_pids()


def test_a_worker_that_died_is_replaced_and_the_check_still_answers() -> None:
    document = factories.valid_document()
    checking.checked(document, checking.interactive_budget())
    for pid in worker_pids():
        os.kill(pid, signal.SIGKILL)

    report = checking.checked(document, checking.interactive_budget())

    assert report["valid"] is True
