"""The operator's hot endpoints read as many times for ten rows as for one: no per-row query.

Each test measures an endpoint, adds nine more of the rows it shows (work items, cases,
incidents, queued jobs), and measures again.
"""

from collections.abc import Callable
from typing import Any

import pytest
from django.contrib.auth.models import User
from django.db import connection
from django.test.utils import CaptureQueriesContext
from rest_framework.test import APIClient

from hrc.cases import services
from hrc.cases.models import Case, WorkItem
from hrc.cobots.models import Cobot
from hrc.organisations.models import Organisation
from hrc.patterns.models import PatternVersion
from tests import factories

pytestmark = pytest.mark.django_db


class Queries:
    """The SQL statements a request ran; equal to another's when as many (the ids differ)."""

    def __init__(self, request: Callable[[], Any]) -> None:
        with CaptureQueriesContext(connection) as captured:
            response = request()
        assert response.status_code == 200, response.data
        self.statements = [query["sql"] for query in captured.captured_queries]

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Queries) and len(self.statements) == len(other.statements)

    def __repr__(self) -> str:
        shown = "\n  ".join(sql[:160] for sql in self.statements)
        return f"{len(self.statements)} queries:\n  {shown}"


def parallel_document(branches: int) -> dict[str, Any]:
    """The operator splits the work into `branches` tasks at once, the cobot's and operators'
    in turn, then joins them: `branches` open work items in one case."""
    document = factories.valid_document()
    places: list[dict[str, Any]] = [{"id": "start", "tokens": 1}, {"id": "end"}]
    transitions = [
        {"id": "split", "performer": "o", "label": "split"},
        {"id": "join", "performer": "o", "label": "join"},
    ]
    arcs = [["start", "split"], ["join", "end"]]
    for n in range(branches):
        places += [{"id": f"before{n}"}, {"id": f"after{n}"}]
        transitions.append({"id": f"t{n}", "performer": "o" if n % 2 else "c", "label": f"t{n}"})
        arcs += [["split", f"before{n}"], [f"before{n}", f"t{n}"], [f"t{n}", f"after{n}"]]
        arcs.append([f"after{n}", "join"])
    document["processes"][0].update(places=places, transitions=transitions, arcs=arcs)
    document["constraints"] = []
    del document["declared_pattern"]
    return document


def split_case(version: PatternVersion, operator: User, cobot: Cobot) -> Case:
    """A case of a parallel_document version whose split is done: its branches are open."""
    mapping = {"o": {"users": [operator.pk]}, "c": {"cobot": cobot.pk}}
    case = factories.make_case(version, started_by=operator, actor_mapping=mapping)
    split = factories.open_work_item(case, "split")
    services.start_work_item(split, user=operator)
    services.complete_work_item(split, user=operator)
    return case


@pytest.fixture
def client(operator: User) -> APIClient:
    client = APIClient()
    client.force_authenticate(operator)
    return client


@pytest.fixture
def hand_over(organisation: Organisation, engineer: User) -> PatternVersion:
    return factories.make_version(organisation, published_by=engineer)


def test_the_task_list_reads_as_often_for_ten_tasks_as_for_one(
    client: APIClient, operator: User, cobot: Cobot, hand_over: PatternVersion
) -> None:
    def cases(count: int) -> None:  # an operator's task and a queued cobot step each
        for _ in range(count):
            factories.make_case(hand_over, started_by=operator,
                                actor_mapping={"o": {"users": [operator.pk]}, "c": {"cobot": cobot.pk}})  # fmt: skip
            factories.hand_over_case(hand_over, started_by=operator, operator=operator, cobot=cobot)

    def task_list() -> Any:
        return client.get("/api/work-items/?kind=operator,step")

    cases(1)
    one = Queries(task_list)
    cases(9)
    assert len(task_list().data["results"]) == 20
    assert Queries(task_list) == one


def test_starting_and_completing_a_task_read_as_often_beside_ten_cases_as_beside_one(
    client: APIClient, operator: User, cobot: Cobot, hand_over: PatternVersion
) -> None:
    # The completion queues the cobot's step behind the others' (or leases it): the hot path.
    def others(count: int) -> None:
        for _ in range(count):
            factories.hand_over_case(hand_over, started_by=operator, operator=operator, cobot=cobot)

    def start_and_complete() -> tuple[Queries, Queries]:
        case = factories.make_case(hand_over, started_by=operator,
                                   actor_mapping={"o": {"users": [operator.pk]}, "c": {"cobot": cobot.pk}})  # fmt: skip
        item = factories.open_work_item(case, "to1")
        started = Queries(lambda: client.post(f"/api/work-items/{item.pk}/start/"))
        completed = Queries(lambda: client.post(f"/api/work-items/{item.pk}/complete/", {}, format="json"))  # fmt: skip
        return started, completed

    others(1)
    one = start_and_complete()
    others(9)
    assert start_and_complete() == one


def test_a_case_reads_as_often_with_ten_open_tasks_and_incidents_as_with_one(
    client: APIClient, organisation: Organisation, engineer: User, operator: User, cobot: Cobot
) -> None:
    def case_with(branches: int) -> Case:
        draft = parallel_document(branches)
        version = factories.make_version(organisation, published_by=engineer, draft=draft)
        case = split_case(version, operator, cobot)
        for item in WorkItem.objects.filter(case=case, task__startswith="t"):
            factories.make_incident(item)
        return case

    def detail(case: Case) -> Callable[[], Any]:
        return lambda: client.get(f"/api/cases/{case.pk}/")

    one = Queries(detail(case_with(1)))
    ten = case_with(10)
    assert len(detail(ten)().data["work_items"]) == len(detail(ten)().data["incidents"]) == 10
    assert Queries(detail(ten)) == one
