"""Checks run in the engine's worker processes, off the server's threads."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

from django.conf import settings

from hrc.engine.check import report_of
from hrc.patterns import checking
from hrc.patterns.engine_workers import worker_pids
from tests import factories


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
    deadline = time.monotonic() + 10
    while alive(worker) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert not alive(worker)


def alive(pid: int) -> bool:
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except FileNotFoundError:
        return False
    return stat.rsplit(")", 1)[1].split()[0] != "Z"  # a zombie waits only for its reaping


def test_a_worker_outlives_the_request_thread_that_started_it() -> None:
    # A server's request threads end; a worker tied to its thread (PR_SET_PDEATHSIG) died
    # with the first request's, and every check after it failed.
    document = factories.valid_document()
    started = threading.Thread(target=checking.checked, args=(document, checking.publish_budget()))
    started.start()
    started.join()
    before = worker_pids()

    report = checking.checked(document, checking.publish_budget())

    assert report["valid"] is True
    assert set(before) <= set(worker_pids())
