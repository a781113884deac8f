"""dispatch sends tasks by name: each name it can send is a task the Celery app has registered."""

import pytest
from django.conf import settings

from hrc.cases import dispatch
from hrc.cases.dispatch import Task
from hrc.celery import app


@pytest.mark.parametrize("task", list(Task))
def test_every_name_dispatch_can_send_is_a_registered_task(task: Task) -> None:
    assert task.value in app.tasks, f"{task.value} is sent but no task is registered under it"
    assert dispatch.registered(task).name == task.value


def test_every_task_of_the_cases_app_has_a_name_dispatch_knows() -> None:
    ours = {name for name in app.tasks if name.startswith("hrc.cases.")}
    assert ours == {task.value for task in Task}


def test_the_beat_schedule_names_registered_tasks() -> None:
    for entry in settings.CELERY_BEAT_SCHEDULE.values():
        assert entry["task"] in app.tasks


def test_a_name_nobody_registered_fails_before_anything_is_sent() -> None:
    with pytest.raises(KeyError):
        app.tasks["hrc.cases.tasks.run_jobs"]
