"""Real Celery workers, a private broker and simulated cobots for the runtime tests.

Each test that uses workers gets its own redis-server, so workers of two
tests running at once (pytest-xdist, a second checkout) never take each
other's messages, and a test can restart its broker without harming others.
Such tests need `django_db(transaction=True)`: the workers are other
processes and see only what is committed.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from pathlib import Path

import pytest
from django.db import connection

from hrc.celery import app
from tests.support.workers import RedisProcess, WorkerProcess


@pytest.fixture
def broker(tmp_path: Path) -> Iterator[RedisProcess]:
    server = RedisProcess(tmp_path).start()
    previous = app.conf.broker_url
    _point_celery_at(server.url)
    yield server
    _point_celery_at(previous)
    server.stop()


def _point_celery_at(url: str) -> None:
    # Celery caches its connection and producer pools; drop them so the next
    # send opens a connection to `url`.
    app.close()
    app.conf.broker_url = url
    app.amqp._producer_pool = None


@pytest.fixture
def start_worker(
    broker: RedisProcess, tmp_path: Path, transactional_db: None
) -> Iterator[Callable[..., WorkerProcess]]:
    """Starts workers on this test's database and broker; all are stopped at the end."""
    started: list[WorkerProcess] = []
    environment = {
        "DJANGO_SETTINGS_MODULE": "hrc.settings.test",
        "DATABASE_URL": f"postgres://postgres@127.0.0.1:5432/{connection.settings_dict['NAME']}",
        "REDIS_URL": broker.url,
        "HRC_SWEEP_SECONDS": "0.5",
        "HRC_JOB_LEASE_MARGIN": "2",
        "HRC_RETRY_BACKOFF": "0.2",
    }

    def start(name: str = "worker", *, beat: bool = False) -> WorkerProcess:
        worker = WorkerProcess(
            tmp_path, name=f"{name}{len(started)}", environment=environment, beat=beat
        )
        started.append(worker.start())
        return worker

    yield start
    for worker in started:
        worker.kill()
