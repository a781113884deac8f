"""The Celery application; tasks live in each app's tasks.py."""

import os
from typing import Any

from celery import Celery
from celery.signals import task_postrun, task_prerun, worker_process_init, worker_ready
from django.db import close_old_connections

from hrc.process import freeze_start_up

os.environ.setdefault("DJANGO_SETTINGS_MODULE", "hrc.settings.dev")

app = Celery("hrc")
app.config_from_object("django.conf:settings", namespace="CELERY")
app.autodiscover_tasks()


def _close_old_connections(task: Any = None, **kwargs: Any) -> None:
    """A task is a request: its connection goes back to the pool (or, unpooled, is closed
    past CONN_MAX_AGE or when an error broke it).

    (Celery's fix-up would close the pool itself; CELERY_DB_REUSE_MAX stops it.)
    Not for an eager task: it runs inside its caller's request, perhaps in a transaction.
    """
    if getattr(getattr(task, "request", None), "is_eager", False):
        return
    close_old_connections()


task_prerun.connect(_close_old_connections)
task_postrun.connect(_close_old_connections)


def _freeze_start_up(**kwargs: Any) -> None:
    """The worker's main process, which takes the messages from the broker, once ready, and
    each pool child once forked and set up (hrc/process.py)."""
    freeze_start_up()


worker_process_init.connect(_freeze_start_up)
worker_ready.connect(_freeze_start_up)
