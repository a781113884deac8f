"""Every cases endpoint against the outsider: 404 for each object, empty lists, nothing changed.

The outsider is an engineer of another organisation, so a 404 is the wall and
not a missing role; the same calls by our own admin are the positive control.
"""

from dataclasses import dataclass
from typing import Any

import pytest
from django.contrib.auth.models import User
from rest_framework.test import APIClient

from hrc.cases.choices import CaseStatus, WorkItemState
from hrc.cases.models import Case, Incident, Job, Message, WorkItem
from hrc.cobots.models import Cobot
from hrc.organisations.models import Organisation
from hrc.patterns.models import PatternVersion
from tests import factories


@dataclass
class World:
    """A running hand-over case of the home organisation, its cobot step queued, an incident."""

    version: PatternVersion
    case: Case
    item: WorkItem
    step: WorkItem
    job: Job
    incident: Incident
    cobot: Cobot

    @property
    def ids(self) -> dict[str, int]:
        return {
            "version": self.version.pk,
            "case": self.case.pk,
            "item": self.item.pk,
            "step": self.step.pk,
            "job": self.job.pk,
            "incident": self.incident.pk,
            "cobot": self.cobot.pk,
        }

    def assert_untouched(self) -> None:
        self.case.refresh_from_db()
        self.item.refresh_from_db()
        self.incident.refresh_from_db()
        self.version.refresh_from_db()
        assert self.case.status == CaseStatus.RUNNING
        assert self.item.state == WorkItemState.OFFERED
        assert self.incident.resolved_at is None
        assert self.version.default_actor_mapping == {}


@pytest.fixture
def world(organisation: Organisation, engineer: User, operator: User) -> World:
    cobot = factories.make_cobot(organisation)
    version = factories.make_version(organisation, published_by=engineer)
    # Cases: one with its operator task open, one whose cobot step failed, one whose runs.
    mapping = {"o": {"users": [operator.pk]}, "c": {"cobot": cobot.pk}}
    case = factories.make_case(version, started_by=engineer, actor_mapping=mapping)
    stepped = factories.make_case(version, started_by=engineer, actor_mapping=mapping)
    first = factories.open_work_item(stepped, "to1")
    client = APIClient()
    client.force_authenticate(operator)
    client.post(f"/api/work-items/{first.pk}/start/")
    client.post(f"/api/work-items/{first.pk}/complete/")
    step = factories.open_work_item(stepped, "tc1")
    incident = factories.make_incident(step)  # its step failed: a person decides
    # A third case's step on the cobot (taken by the completion): the queues list it.
    factories.hand_over_case(version, started_by=engineer, operator=operator, cobot=cobot)
    return World(
        version, case, factories.open_work_item(case, "to1"), step, step.job, incident, cobot
    )


@dataclass(frozen=True)
class Endpoint:
    method: str
    path: str
    body: Any = None

    def call(self, client: APIClient, ids: dict[str, int]) -> Any:
        return getattr(client, self.method)(self.path.format(**ids), self.body, format="json")

    def __str__(self) -> str:
        return f"{self.method.upper()} {self.path}"


OBJECT_ENDPOINTS = [
    Endpoint("get", "/api/cases/{case}/"),
    Endpoint("get", "/api/cases/{case}/events/"),
    Endpoint("post", "/api/cases/{case}/cancel/"),
    Endpoint("post", "/api/cases/{case}/suspend/"),
    Endpoint("post", "/api/cases/{case}/resume/"),
    Endpoint("get", "/api/work-items/{item}/"),
    Endpoint("get", "/api/work-items/{step}/"),
    Endpoint("post", "/api/work-items/{item}/claim/"),
    Endpoint("post", "/api/work-items/{item}/unclaim/"),
    Endpoint("post", "/api/work-items/{item}/start/"),
    Endpoint("post", "/api/work-items/{item}/complete/", {"data": {}}),
    Endpoint("post", "/api/work-items/{item}/reassign/", {"user": None}),
    Endpoint("post", "/api/work-items/{item}/left-area/"),
    Endpoint("get", "/api/work-items/{item}/performers/"),
    Endpoint("get", "/api/incidents/{incident}/"),
    Endpoint("post", "/api/incidents/{incident}/resolve/", {"resolution": "cancel"}),
    Endpoint("get", "/api/jobs/{job}/"),
    Endpoint("get", "/api/pattern-versions/{version}/actor-mapping/"),
    Endpoint(
        "put",
        "/api/pattern-versions/{version}/actor-mapping/",
        {"actor_mapping": {"o": {"users": ["oscar-outsider"]}, "c": {"cobot": "x"}}},
    ),
]
LIST_ENDPOINTS = [
    "/api/cases/",
    "/api/cases/?status=running",
    "/api/work-items/",
    "/api/work-items/?kind=operator,step,device",
    "/api/work-items/?case={case}",
    "/api/incidents/",
    "/api/incidents/?all=1",
    "/api/jobs/",
    "/api/jobs/?cobot={cobot}",
]


@pytest.mark.parametrize("endpoint", OBJECT_ENDPOINTS, ids=str)
def test_an_outsider_gets_404_for_every_case_object_of_another_organisation(
    outsider_client: APIClient, world: World, endpoint: Endpoint
) -> None:
    response = endpoint.call(outsider_client, world.ids)
    assert response.status_code == 404
    assert set(response.data) == {"detail"}
    world.assert_untouched()


@pytest.mark.parametrize("endpoint", OBJECT_ENDPOINTS, ids=str)
def test_our_admin_gets_past_the_wall_on_every_endpoint(
    admin_client: APIClient, world: World, endpoint: Endpoint
) -> None:
    # The positive control: the 404s above are the wall, not a broken URL.
    assert endpoint.call(admin_client, world.ids).status_code != 404


@pytest.mark.parametrize("path", LIST_ENDPOINTS)
def test_an_outsider_sees_nothing_of_another_organisation_in_lists(
    outsider_client: APIClient, admin_client: APIClient, world: World, path: str
) -> None:
    url = path.format(**world.ids)
    response = outsider_client.get(url)
    assert response.status_code == 200
    assert (response.data["count"], response.data["results"]) == (0, [])
    if "work-items" not in url:  # the admin is no candidate: their task list is empty anyway
        assert admin_client.get(url).data["count"] > 0


def test_an_outsider_cannot_start_a_case_of_our_version(
    outsider_client: APIClient, world: World, outsider: User
) -> None:
    body = {"version": world.version.pk, "actor_mapping": {"o": {"users": [outsider.pk]}}}
    cases = Case.objects.count()
    response = outsider_client.post("/api/cases/", body, format="json")
    # Nothing is looked up by the URL: the version in the body is simply unknown to them.
    assert response.status_code == 400
    assert "version" in response.data["fields"]
    assert Case.objects.count() == cases


def test_an_outsiders_message_never_reaches_our_cases(
    outsider_client: APIClient, world: World, organisation: Organisation
) -> None:
    body = {"message_id": "x-1", "name": "part-ready", "organisation": organisation.pk}
    response = outsider_client.post("/api/messages/", body, format="json")
    assert response.status_code == 400
    assert "organisation" in response.data["fields"]
    # Without naming one it goes to their own organisation.
    body.pop("organisation")
    response = outsider_client.post("/api/messages/", body, format="json")
    assert response.status_code == 201
    assert Message.objects.get().organisation_id != organisation.pk


def test_an_anonymous_request_is_a_401(anonymous_client: APIClient, world: World) -> None:
    for path in ("/api/cases/", "/api/work-items/", "/api/incidents/", "/api/jobs/"):
        assert anonymous_client.get(path).status_code == 401
    assert anonymous_client.post("/api/messages/", {}, format="json").status_code == 401
