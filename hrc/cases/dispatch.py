"""The one way case services hand work to the background: after the transaction commits.

The broker is a doorbell, never the truth: a message lost here (Redis
restarting) costs only latency, because the sweeper (jobs.sweep) finds every
job that is due from the rows themselves. So a failed send is logged, not raised.

`run_inline` swaps Celery for a thread pool in this process (run_pattern
without workers, and the embedded demo); everything else stays the same.
The embedded demo has no Celery beat either: `start_embedded_sweeper` runs
the sweeper on a thread of the server instead.

Tasks go by their registered name (Task), never by importing tasks.py, which
imports the modules that send them; tests/cases/test_dispatch.py checks that
every name is a registered task.
"""

from __future__ import annotations

import functools
import logging
import threading
import time
from collections.abc import Callable, Iterator
from concurrent.futures import Executor, ThreadPoolExecutor
from contextlib import contextmanager
from enum import StrEnum
from typing import Any

from celery import Task as CeleryTask
from django.conf import settings
from django.db import connections, transaction

from hrc.celery import app

logger = logging.getLogger(__name__)

_inline: Executor | None = None


class Task(StrEnum):
    """The Celery tasks of the cases app, by the names tasks.py registers them under."""

    RUN_JOB = "hrc.cases.tasks.run_job"
    RUN_LEASED_JOB = "hrc.cases.tasks.run_leased_job"
    SWEEP = "hrc.cases.tasks.sweep"
    INTERRUPT_COBOT = "hrc.cases.tasks.interrupt_cobot"
    RESUME_COBOT = "hrc.cases.tasks.resume_cobot"
    PURGE_MESSAGES = "hrc.cases.tasks.purge_messages"
    DELIVER_MESSAGE = "hrc.cases.tasks.deliver_message"
    RING_TIMER = "hrc.cases.tasks.ring_timer"


def send_on_commit(task: Task, *args: Any, countdown: float = 0) -> None:
    """Sends the Celery task `task`(*args) once the transaction commits."""
    transaction.on_commit(lambda: _send(task, args, countdown))


def send_on_commit_if(wanted: Callable[[], bool], task: Task, *args: Any) -> None:
    """send_on_commit, when `wanted()`, asked once the transaction has committed, says so."""

    def send() -> None:
        if wanted():
            _send(task, args, 0)

    transaction.on_commit(send)


def _send(task: Task, args: tuple[Any, ...], countdown: float) -> None:
    executor = _inline
    if executor is None and settings.HRC_INLINE_TASKS:
        executor = _embedded_pool()
        start_embedded_sweeper()
    if executor is not None:
        _submit_inline(executor, registered(task).run, args, countdown)
        return
    try:
        # The cases' tasks keep no results (ignore_result on each), so nothing of what Celery
        # prepares for a result is wanted: its object (a result backend made per thread, and a
        # request runs on a thread of its own), the reply address (derived per thread) and a
        # parent's list of children. Nor its safe repr of the arguments, small dicts and ints
        # here. Together about half of a send's CPU in a request (bench/README.md).
        app.send_task(
            task.value, args, countdown=countdown or None, ignore_result=True,
            argsrepr=repr(args), reply_to=NO_REPLY, result_cls=_Sent, add_to_parent=False,
        )  # fmt: skip
    except Exception as error:  # the broker is down: the sweeper will find the row
        logger.warning("Could not send %s%s (%s); the sweeper will", task.value, args, error)


# The reply address of a message whose task keeps no result: nothing is ever sent to it.
NO_REPLY = "hrc.no-reply"


class _Sent:
    """What send_task returns for a message sent (its id): there is no result to wait for."""

    def __init__(self, task_id: str) -> None:
        self.id = task_id
        self.ignored = True


def registered(task: Task) -> CeleryTask:
    """The Celery task of that name, as the app registered it (hrc.cases.receivers imports
    tasks.py at start-up, so it is there in every process). KeyError when it is not."""
    return app.tasks[task.value]


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

    def submit() -> None:
        try:
            executor.submit(call)
        except RuntimeError:
            # The pool is shut down: the process is exiting (the embedded sweeper's or a
            # timer's daemon thread woke after the interpreter began its shutdown). What the
            # task would do is left in the rows, for the next process's sweeper.
            logger.debug("Not run, the process is exiting: %s", run)

    if countdown:
        timer = threading.Timer(countdown, submit)
        timer.daemon = True
        timer.start()
    else:
        submit()


@functools.cache
def _embedded_pool() -> Executor:
    return ThreadPoolExecutor(max_workers=4, thread_name_prefix="hrc-jobs")


@functools.cache
def start_embedded_sweeper() -> threading.Thread:
    """Runs the sweeper every HRC_SWEEP_SECONDS on the embedded pool, for the life of the process.

    Without it a job whose doorbell was lost (the server stopped mid-case)
    would wait forever. Once per process; the server calls it at start-up.
    """

    def ring() -> None:
        while True:
            time.sleep(settings.HRC_SWEEP_SECONDS)
            if settings.HRC_INLINE_TASKS:  # settings can change under tests
                _submit_inline(_embedded_pool(), registered(Task.SWEEP).run, (), 0)

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
