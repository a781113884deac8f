"""Many tablets at once: the case row lock lets exactly one completion of a work item through."""

import threading
from collections import Counter
from typing import Any

import pytest
from django.contrib.auth.models import User
from django.db import connection
from rest_framework.test import APIClient

from hrc.cases import services
from hrc.cases.choices import EventType, WorkItemState
from hrc.cases.models import CaseEvent, WorkItem
from hrc.organisations.choices import Role
from tests import factories

ATTEMPTS = 50


@pytest.mark.django_db(transaction=True)
def test_fifty_concurrent_completions_of_one_work_item_let_exactly_one_through() -> None:
    organisation = factories.make_organisation()
    engineer = factories.make_member(organisation, Role.ENGINEER)
    operator = factories.make_member(organisation, Role.OPERATOR)
    version = factories.make_version(
        organisation, published_by=engineer, draft=factories.choice_document()
    )
    case = factories.make_case(
        version, started_by=engineer, actor_mapping={"o": {"users": [operator.pk]}}
    )
    item = factories.open_work_item(case, "count")
    services.start_work_item(item, user=operator)

    # The same operator on fifty tablets, so only the lock can tell the completions apart.
    barrier = threading.Barrier(ATTEMPTS)
    answers: list[tuple[int, Any]] = []
    failures: list[BaseException] = []

    def complete(user: User, count: int) -> None:
        client = APIClient()
        client.force_authenticate(user)
        try:
            barrier.wait(timeout=30)
            response = client.post(
                f"/api/work-items/{item.pk}/complete/", {"data": {"count": count}}, format="json"
            )
            answers.append((response.status_code, response.data))
        except BaseException as error:  # reported below: a thread's exception is otherwise lost
            failures.append(error)
        finally:
            connection.close()

    threads = [
        threading.Thread(target=complete, args=(operator, n)) for n in range(1, ATTEMPTS + 1)
    ]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join(timeout=60)

    assert not failures
    assert Counter(code for code, _ in answers) == {200: 1, 409: ATTEMPTS - 1}
    conflicts = [data["detail"] for code, data in answers if code == 409]
    assert set(conflicts) == {"count parts cannot be completed: it is completed now."}
    winner = next(data for code, data in answers if code == 200)
    item.refresh_from_db()
    assert item.state == WorkItemState.COMPLETED
    assert item.result == winner["result"]
    completed = CaseEvent.objects.filter(case=case, type=EventType.TASK_COMPLETED, work_item=item)
    assert completed.count() == 1
    # The case moved on once: the choice is offered once, not twice.
    offered = WorkItem.objects.filter(case=case, state=WorkItemState.OFFERED)
    assert sorted(offered.values_list("task", flat=True)) == ["fix", "rework"]
