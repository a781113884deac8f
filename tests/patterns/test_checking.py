"""Checks run in the engine's worker processes, off the server's threads."""

from __future__ import annotations

import os
import signal
import subprocess
import sys

from django.conf import settings

from hrc.engine.check import report_of
from hrc.patterns import checking
from hrc.patterns.engine_workers import worker_pids
from tests import factories
from tests.demo.rig import alive
from tests.support.polling import until


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
    dead = worker_pids()
    for pid in dead:
        os.kill(pid, signal.SIGKILL)

    report = checking.checked(document, checking.interactive_budget())

    assert report["valid"] is True
    assert not set(dead) & set(worker_pids())


PARENT = """
import sys, time, django
django.setup()
from hrc.patterns import checking
from hrc.patterns.engine_workers import worker_pids
from tests import factories
from tests.demo.rig import alive
checking.checked(factories.valid_document(), checking.interactive_budget())
print(worker_pids()[0], flush=True)
time.sleep(60)
"""


def test_a_worker_dies_with_a_server_killed_outright() -> None:
    parent = subprocess.Popen(
        [sys.executable, "-c", PARENT], stdout=subprocess.PIPE, text=True, cwd=settings.BASE_DIR
    )
    assert parent.stdout is not None
    worker = int(parent.stdout.readline())
    parent.kill()
    parent.wait()
    until(lambda: not alive(worker), timeout=10, interval=0.05)
    assert not alive(worker)
