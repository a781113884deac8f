"""The cases API: start, list, detail, cancel, suspend, resume, the event log, actor mappings."""

from typing import Any

import pytest
from django.contrib.auth.models import User
from rest_framework.test import APIClient

from hrc.cases import services as case_services
from hrc.cases.choices import CaseStatus, EventType, WorkItemState
from hrc.cases.models import Case, WorkItem
from hrc.organisations import services as organisation_services
from hrc.organisations.choices import Role
from hrc.organisations.models import Organisation
from hrc.patterns.models import PatternVersion
from tests import factories


def _start(client: APIClient, version: PatternVersion, **body: Any) -> Any:
    return client.post("/api/cases/", {"version": version.pk, **body}, format="json")


# Starting ------------------------------------------------------------------------------


@pytest.mark.parametrize("persona", ["engineer", "admin"])
def test_an_engineer_or_admin_starts_a_case_that_offers_its_first_task(
    request: pytest.FixtureRequest, choice_version: PatternVersion, operator: User, persona: str
) -> None:
    client = request.getfixturevalue(f"{persona}_client")
    mapping = {"o": {"users": [operator.username]}}
    response = _start(client, choice_version, actor_mapping=mapping, data={"tray": 7})
    assert response.status_code == 201, response.data
    case = Case.objects.get(pk=response.data["id"])
    assert (case.status, case.data, case.started_by) == (
        CaseStatus.RUNNING,
        {"tray": 7},
        request.getfixturevalue(persona),
    )
    assert case.actor_mapping == {"o": {"users": [operator.pk]}}  # names stored as ids
    assert [(w["task"], w["state"]) for w in response.data["work_items"]] == [("count", "offered")]
    assert response.data["marking"] == case.marking
    assert (response.data["pattern_name"], response.data["version_number"]) == (
        choice_version.pattern.name,
        1,
    )


def test_an_operator_cannot_start_a_case(
    operator_client: APIClient, choice_version: PatternVersion, operator: User
) -> None:
    response = _start(
        operator_client, choice_version, actor_mapping={"o": {"users": [operator.pk]}}
    )
    assert response.status_code == 403
    assert not Case.objects.exists()


def test_an_engineer_elsewhere_who_is_an_operator_here_cannot_start_a_case(
    choice_version: PatternVersion, operator: User, other_organisation: Organisation
) -> None:
    # An engineer elsewhere passes the "writes somewhere" gate; the version's organisation decides.
    organisation_services.add_member(other_organisation, operator, Role.ENGINEER)
    client = APIClient()
    client.force_authenticate(operator)
    response = _start(client, choice_version, actor_mapping={"o": {"users": [operator.pk]}})
    assert response.status_code == 403
    assert not Case.objects.exists()


def test_an_unmapped_actor_is_a_400_naming_it(
    engineer_client: APIClient, choice_version: PatternVersion
) -> None:
    response = _start(engineer_client, choice_version)
    assert response.status_code == 400
    assert "Actor o (operator) is not mapped" in response.data["detail"]
    assert not Case.objects.exists()


@pytest.mark.parametrize(
    ("body", "field"),
    [
        ({"data": [1, 2]}, "data"),
        ({"actor_mapping": {"o": "anna"}}, "actor_mapping"),
        ({"version": 99999999}, "version"),
        ({"version": "abc"}, "version"),
    ],
)
def test_a_malformed_start_is_a_400_naming_the_field(
    engineer_client: APIClient, choice_version: PatternVersion, body: dict[str, Any], field: str
) -> None:
    response = engineer_client.post(
        "/api/cases/", {"version": choice_version.pk, **body}, format="json"
    )
    assert response.status_code == 400
    assert field in response.data["fields"]


def test_the_versions_default_mapping_is_used_and_a_case_overrides_it(
    engineer_client: APIClient, choice_version: PatternVersion, operator: User, admin: User
) -> None:
    response = engineer_client.put(
        f"/api/pattern-versions/{choice_version.pk}/actor-mapping/",
        {"actor_mapping": {"o": {"users": [operator.username]}}},
        format="json",
    )
    assert response.status_code == 200, response.data
    assert response.data == {
        "version": choice_version.pk,
        "actor_mapping": {"o": {"users": [operator.pk]}},
    }
    default = _start(engineer_client, choice_version).data
    assert default["actor_mapping"] == {"o": {"users": [operator.pk]}}
    overridden = _start(engineer_client, choice_version, actor_mapping={"o": {"users": [admin.pk]}})
    assert overridden.data["actor_mapping"] == {"o": {"users": [admin.pk]}}


def test_members_read_the_default_mapping_and_operators_cannot_change_it(
    operator_client: APIClient, choice_version: PatternVersion, operator: User
) -> None:
    url = f"/api/pattern-versions/{choice_version.pk}/actor-mapping/"
    assert operator_client.get(url).data == {"version": choice_version.pk, "actor_mapping": {}}
    body = {"actor_mapping": {"o": {"users": [operator.pk]}}}
    assert operator_client.put(url, body, format="json").status_code == 403
    choice_version.refresh_from_db()
    assert choice_version.default_actor_mapping == {}


def test_a_mapping_to_someone_outside_the_organisation_is_a_400(
    engineer_client: APIClient, choice_version: PatternVersion, outsider: User
) -> None:
    response = engineer_client.put(
        f"/api/pattern-versions/{choice_version.pk}/actor-mapping/",
        {"actor_mapping": {"o": {"users": [outsider.pk]}}},
        format="json",
    )
    assert response.status_code == 400
    assert "not an active member of the organisation" in response.data["detail"]


# Reading ---------------------------------------------------------------------------------


def test_members_list_cases_filtered_by_status_and_version(
    operator_client: APIClient, choice_case: Case, engineer: User, operator: User
) -> None:
    other_version = factories.make_version(
        choice_case.organisation, published_by=engineer, draft=factories.choice_document()
    )
    other = factories.make_case(
        other_version, started_by=engineer, actor_mapping={"o": {"users": [operator.pk]}}
    )
    case_services.cancel_case(other, by=engineer)

    def ids(query: str) -> list[int]:
        response = operator_client.get(f"/api/cases/{query}")
        assert response.status_code == 200
        return [c["id"] for c in response.data["results"]]

    assert ids("") == [other.pk, choice_case.pk]  # newest first
    assert ids("?status=running") == [choice_case.pk]
    assert ids("?status=cancelled") == [other.pk]
    assert ids(f"?version={other_version.pk}") == [other.pk]
    assert operator_client.get("/api/cases/?status=bogus").status_code == 400
    assert operator_client.get("/api/cases/?version=x").status_code == 400


def test_the_detail_shows_marking_data_open_work_and_open_incidents(
    operator_client: APIClient, choice_case: Case
) -> None:
    item = factories.open_work_item(choice_case, "count")
    incident = factories.make_incident(item, "Tray missing")
    response = operator_client.get(f"/api/cases/{choice_case.pk}/")
    assert response.status_code == 200
    assert response.data["marking"] == {"p1": 1}
    assert response.data["status"] == "running"
    assert [w["id"] for w in response.data["work_items"]] == [item.pk]
    assert [(i["id"], i["message"]) for i in response.data["incidents"]] == [
        (incident.pk, "Tray missing")
    ]


# The event log ---------------------------------------------------------------------------


def test_the_event_log_is_in_order_and_after_gives_only_newer_events(
    operator_client: APIClient, choice_case: Case, operator: User
) -> None:
    url = f"/api/cases/{choice_case.pk}/events/"
    first = operator_client.get(url).data
    assert [e["type"] for e in first["results"]] == [
        EventType.CASE_STARTED,
        EventType.TASK_OFFERED,
    ]
    assert [e["seq"] for e in first["results"]] == [1, 2]
    item = factories.open_work_item(choice_case, "count")
    operator_client.post(f"/api/work-items/{item.pk}/start/")
    newer = operator_client.get(f"{url}?after=2").data
    assert [(e["seq"], e["type"], e["user"]) for e in newer["results"]] == [
        (3, EventType.TASK_STARTED, operator.username)
    ]
    assert newer["results"][0]["marking_after"] != newer["results"][0]["marking_before"]
    assert operator_client.get(f"{url}?after=3").data["results"] == []
    assert operator_client.get(f"{url}?after=-1").status_code == 400


def test_the_event_log_is_paginated(operator_client: APIClient, choice_case: Case) -> None:
    response = operator_client.get(f"/api/cases/{choice_case.pk}/events/?limit=1")
    assert response.data["count"] == 2
    assert [e["seq"] for e in response.data["results"]] == [1]
    assert response.data["next"] is not None


# Cancel, suspend, resume -------------------------------------------------------------------


def test_an_engineer_suspends_and_resumes_a_case_and_nothing_starts_meanwhile(
    engineer_client: APIClient, operator_client: APIClient, choice_case: Case
) -> None:
    item = factories.open_work_item(choice_case, "count")
    response = engineer_client.post(f"/api/cases/{choice_case.pk}/suspend/")
    assert (response.status_code, response.data["status"]) == (200, "suspended")
    refused = operator_client.post(f"/api/work-items/{item.pk}/start/")
    assert refused.status_code == 409
    assert "suspended" in refused.data["detail"]
    again = engineer_client.post(f"/api/cases/{choice_case.pk}/suspend/")
    assert again.status_code == 409
    assert "not running" in again.data["detail"]
    response = engineer_client.post(f"/api/cases/{choice_case.pk}/resume/")
    assert (response.status_code, response.data["status"]) == (200, "running")
    assert operator_client.post(f"/api/work-items/{item.pk}/start/").status_code == 200


def test_an_admin_cancels_a_case_with_a_reason_and_open_work_is_withdrawn(
    admin_client: APIClient, choice_case: Case
) -> None:
    item = factories.open_work_item(choice_case, "count")
    response = admin_client.post(
        f"/api/cases/{choice_case.pk}/cancel/", {"reason": "wrong tray"}, format="json"
    )
    assert response.status_code == 200, response.data
    assert (response.data["status"], response.data["work_items"]) == ("cancelled", [])
    item.refresh_from_db()
    assert item.state == WorkItemState.WITHDRAWN
    assert choice_case.events.get(type=EventType.CASE_CANCELLED).detail == {"reason": "wrong tray"}
    twice = admin_client.post(f"/api/cases/{choice_case.pk}/cancel/")
    assert twice.status_code == 409
    assert "has ended (cancelled)" in twice.data["detail"]


@pytest.mark.parametrize("action", ["cancel", "suspend", "resume"])
def test_an_operator_cannot_steer_a_case(
    operator_client: APIClient, choice_case: Case, action: str
) -> None:
    response = operator_client.post(f"/api/cases/{choice_case.pk}/{action}/")
    assert response.status_code == 403
    choice_case.refresh_from_db()
    assert choice_case.status == CaseStatus.RUNNING
    assert WorkItem.objects.filter(case=choice_case, state=WorkItemState.OFFERED).exists()
