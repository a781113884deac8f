"""The one way case services hand work to the background: after the transaction commits.

The broker is a doorbell, never the truth: a message lost here (Redis
restarting) costs only latency, because the sweeper (jobs.sweep) finds every
job that is due from the rows themselves. So a failed send is logged, not raised.

`run_inline` swaps Celery for a thread pool in this process (run_pattern
without workers, and the embedded demo); everything else stays the same.
The embedded demo has no Celery beat either: `start_embedded_sweeper` runs
the sweeper on a thread of the server instead.
"""

from __future__ import annotations

import functools
import logging
import threading
import time
from collections.abc import Callable, Iterator
from concurrent.futures import Executor, ThreadPoolExecutor
from contextlib import contextmanager
from typing import Any

from django.conf import settings
from django.db import connections, transaction

logger = logging.getLogger(__name__)

_inline: Executor | None = None


def send_on_commit(task_name: str, *args: Any, countdown: float = 0) -> None:
    """Sends the Celery task `hrc.cases.tasks.<task_name>`(*args) once the transaction commits."""
    transaction.on_commit(lambda: _send(task_name, args, countdown))


def send_on_commit_if(wanted: Callable[[], bool], task_name: str, *args: Any) -> None:
    """send_on_commit, when `wanted()`, asked once the transaction has committed, says so."""

    def send() -> None:
        if wanted():
            _send(task_name, args, 0)

    transaction.on_commit(send)


def _send(task_name: str, args: tuple[Any, ...], countdown: float) -> None:
    from hrc.cases import tasks  # the tasks module imports the services that import this one

    task = getattr(tasks, task_name)
    executor = _inline
    if executor is None and settings.HRC_INLINE_TASKS:
        executor = _embedded_pool()
        start_embedded_sweeper()
    if executor is not None:
        _submit_inline(executor, task.run, args, countdown)
        return
    try:
        task.apply_async(args, countdown=countdown or None)
    except Exception as error:  # the broker is down: the sweeper will find the row
        logger.warning("Could not send %s%s (%s); the sweeper will", task_name, args, error)


def _submit_inline(
    executor: Executor, run: Callable[..., Any], args: tuple[Any, ...], countdown: float
) -> None:
    def call() -> None:
        try:
            run(*args)
        except Exception:
            logger.exception("Inline task failed")
        finally:
            # A pool thread's connection would outlive the run (and block dropping the database).
            connections.close_all()

    if countdown:
        timer = threading.Timer(countdown, lambda: executor.submit(call))
        timer.daemon = True
        timer.start()
    else:
        executor.submit(call)


@functools.cache
def _embedded_pool() -> Executor:
    return ThreadPoolExecutor(max_workers=4, thread_name_prefix="hrc-jobs")


@functools.cache
def start_embedded_sweeper() -> threading.Thread:
    """Runs the sweeper every HRC_SWEEP_SECONDS on the embedded pool, for the life of the process.

    Without it a job whose doorbell was lost (the server stopped mid-case)
    would wait forever. Once per process; the server calls it at start-up.
    """
    from hrc.cases import tasks

    def ring() -> None:
        while True:
            time.sleep(settings.HRC_SWEEP_SECONDS)
            if settings.HRC_INLINE_TASKS:  # settings can change under tests
                _submit_inline(_embedded_pool(), tasks.sweep.run, (), 0)

    thread = threading.Thread(target=ring, name="hrc-sweeper", daemon=True)
    thread.start()
    return thread


@contextmanager
def run_inline(executor: Executor) -> Iterator[None]:
    """Runs tasks sent inside this block on `executor` instead of Celery workers."""
    global _inline
    previous, _inline = _inline, executor
    try:
        yield
    finally:
        _inline = previous
