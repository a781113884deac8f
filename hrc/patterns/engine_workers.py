"""The engine's worker processes of a web process: checks run there, off the server's threads.

A check is pure Python that holds the interpreter lock: on a thread of daphne
it slowed every other request of that process, and its markings grew daphne's
memory. Each web process keeps up to HRC_ENGINE_WORKERS workers
(`python -m hrc.engine.worker`, which imports only the engine), started on
first use, each taking one document at a time over a pipe; the request's
thread waits for the answer without holding the lock. Plain pipes, not
multiprocessing: no re-import of the server's main module in the child and no
resource tracker left behind; a worker ends with its parent's pipe (hrc.engine.worker).

A worker is replaced after CHECKS_PER_WORKER checks, so the memory a huge
state space took goes back to the system, and when it dies or overruns its
budget by OVERRUN_SECONDS (then it is killed).
"""

from __future__ import annotations

import atexit
import contextlib
import json
import os
import subprocess
import sys
import threading
from typing import IO

from django.conf import settings

from hrc.engine.budget import Budget
from hrc.patterns.documents import Report

CHECKS_PER_WORKER = 50
# Past its budget a check that has not answered is stuck: its worker is killed.
OVERRUN_SECONDS = 30.0


class EngineWorkerFailed(Exception):
    """The worker died or was stuck; the message says which, for the server's log."""


class _Worker:
    def __init__(self) -> None:
        self.process = subprocess.Popen(
            [sys.executable, "-m", "hrc.engine.worker"],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            cwd=settings.BASE_DIR,
        )
        self.checks = 0

    def check(self, document: object, budget: Budget) -> Report:
        request = {"document": document, "seconds": budget.seconds, "markings": budget.max_markings}
        stdin, stdout = self._pipes()
        overrun = (budget.seconds or 3600.0) + OVERRUN_SECONDS
        watchdog = threading.Timer(overrun, self.process.kill)
        watchdog.start()
        try:
            stdin.write(json.dumps(request).encode() + b"\n")
            stdin.flush()
            answer = stdout.readline()
        except OSError as error:
            raise EngineWorkerFailed(f"the engine worker's pipe broke: {error}") from None
        finally:
            watchdog.cancel()
        if not answer:
            raise EngineWorkerFailed("the engine worker ended without an answer")
        self.checks += 1
        report: Report = json.loads(answer)
        return report

    def _pipes(self) -> tuple[IO[bytes], IO[bytes]]:
        assert self.process.stdin is not None
        assert self.process.stdout is not None
        return self.process.stdin, self.process.stdout

    def stop(self) -> None:
        if self.process.stdin is not None:
            with contextlib.suppress(OSError):  # a dead worker's pipe cannot take the rest
                self.process.stdin.close()  # the worker's loop ends
        try:
            self.process.wait(1)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()


class _Pool:
    """This process's workers: at most HRC_ENGINE_WORKERS, each busy with one check."""

    def __init__(self) -> None:
        self.owner = os.getpid()
        self.free = threading.BoundedSemaphore(settings.HRC_ENGINE_WORKERS)
        self.guard = threading.Lock()
        self.idle: list[_Worker] = []
        self.all: list[_Worker] = []

    def check(self, document: object, budget: Budget) -> Report:
        with self.free:
            worker = self._take()
            try:
                report = worker.check(document, budget)
            except EngineWorkerFailed:
                self._forget(worker)
                raise
            self._give_back(worker)
            return report

    def _take(self) -> _Worker:
        with self.guard:
            while self.idle:
                worker = self.idle.pop()
                if worker.process.poll() is None:
                    return worker
                self.all.remove(worker)  # ended while idle (killed by hand, out of memory)
            worker = _Worker()
            self.all.append(worker)
            return worker

    def _give_back(self, worker: _Worker) -> None:
        if worker.checks >= CHECKS_PER_WORKER:
            self._forget(worker)
            return
        with self.guard:
            self.idle.append(worker)

    def _forget(self, worker: _Worker) -> None:
        with self.guard:
            self.all.remove(worker)
        worker.stop()

    def stop_idle(self) -> None:
        with self.guard:
            idle, self.idle = self.idle, []
            for worker in idle:
                self.all.remove(worker)
        for worker in idle:
            worker.stop()

    def stop(self) -> None:
        """Ends every worker; at exit, so that none outlives this process."""
        if os.getpid() != self.owner:
            return  # a forked child's copy: the workers are its parent's
        with self.guard:
            workers, self.all, self.idle = self.all, [], []
        for worker in workers:
            worker.stop()


_guard = threading.Lock()
_pool: _Pool | None = None


def check_in_worker(document: object, budget: Budget) -> Report:
    """The engine's report on `document` within `budget`, from one of this process's workers;
    when the worker failed, the idle ones are replaced too and the check is tried once more."""
    pool = _this_process_pool()
    try:
        return pool.check(document, budget)
    except EngineWorkerFailed:
        pool.stop_idle()  # what ended one (an OOM kill, a person's kill) may have ended them all
        return pool.check(document, budget)


def _this_process_pool() -> _Pool:
    """Made on first use; a forked child (a Celery worker) makes its own."""
    global _pool
    with _guard:
        if _pool is None or _pool.owner != os.getpid():
            _pool = _Pool()
            atexit.register(_pool.stop)
        return _pool


def worker_pids() -> list[int]:
    """The pids of this process's engine workers (for tests)."""
    pool = _pool
    return [] if pool is None else [worker.process.pid for worker in pool.all]
