"""Incidents: listed open by default, resolved by engineers and admins (retry, skip, cancel)."""

from typing import Any

import pytest
from rest_framework.test import APIClient

from hrc.cases.choices import CaseStatus, JobState, WorkItemState
from hrc.cases.models import Case, Incident
from tests import factories


@pytest.fixture
def incident(step_case: Case) -> Incident:
    return factories.make_incident(factories.open_work_item(step_case, "tc1"), "Protective stop")


def _resolve(client: APIClient, incident: Incident, **body: object) -> Any:
    return client.post(f"/api/incidents/{incident.pk}/resolve/", body, format="json")


def test_members_list_open_incidents_and_all_on_request(
    operator_client: APIClient, incident: Incident, engineer_client: APIClient
) -> None:
    response = operator_client.get("/api/incidents/")
    assert response.status_code == 200
    assert [(i["id"], i["task"], i["kind"]) for i in response.data["results"]] == [
        (incident.pk, "tc1", "step-failed")
    ]
    assert response.data["results"][0]["cobot_state"] == {"RobotMode": 7}
    _resolve(engineer_client, incident, resolution="retry")
    assert operator_client.get("/api/incidents/").data["results"] == []
    every = operator_client.get("/api/incidents/?all=1").data["results"]
    assert [(i["id"], i["resolution"], i["resolved_by"]) for i in every] == [
        (incident.pk, "retry", "erik-engineer")
    ]
    assert operator_client.get(f"/api/incidents/{incident.pk}/").status_code == 200


def test_an_operator_cannot_resolve_an_incident(
    operator_client: APIClient, incident: Incident
) -> None:
    assert _resolve(operator_client, incident, resolution="cancel").status_code == 403
    incident.refresh_from_db()
    assert incident.resolved_at is None
    assert incident.case.status == CaseStatus.RUNNING


def test_retry_queues_the_job_again_with_a_new_attempt_when_asked(
    engineer_client: APIClient, incident: Incident
) -> None:
    job = incident.case.jobs.get()
    job.state, job.last_error = JobState.FAILED, "Protective stop"  # as jobs.fail_job leaves it
    job.save()
    response = _resolve(engineer_client, incident, resolution="retry", again=True)
    assert response.status_code == 200, response.data
    job.refresh_from_db()
    assert (job.state, job.attempt, job.last_error) == (JobState.QUEUED, 2, "")


def test_skip_completes_the_task_with_the_given_outputs(
    admin_client: APIClient, incident: Incident
) -> None:
    response = _resolve(admin_client, incident, resolution="skip", outputs={"placed": True})
    assert response.status_code == 200, response.data
    case = incident.case
    case.refresh_from_db()
    assert (case.status, case.data["tc1"]) == (CaseStatus.COMPLETED, {"placed": True})
    assert case.jobs.get().state == JobState.CANCELLED


def test_cancel_cancels_the_case(engineer_client: APIClient, incident: Incident) -> None:
    assert _resolve(engineer_client, incident, resolution="cancel").status_code == 200
    incident.case.refresh_from_db()
    assert incident.case.status == CaseStatus.CANCELLED
    assert not incident.case.work_items.filter(state=WorkItemState.OFFERED).exists()


def test_a_resolved_incident_cannot_be_resolved_again(
    engineer_client: APIClient, incident: Incident
) -> None:
    _resolve(engineer_client, incident, resolution="retry")
    response = _resolve(engineer_client, incident, resolution="skip")
    assert response.status_code == 409
    assert "was resolved already (retry)" in response.data["detail"]


def test_an_unknown_resolution_is_a_400(engineer_client: APIClient, incident: Incident) -> None:
    response = _resolve(engineer_client, incident, resolution="ignore")
    assert response.status_code == 400
    assert "resolution" in response.data["fields"]


def test_retrying_an_operator_task_is_a_409(engineer_client: APIClient, choice_case: Case) -> None:
    incident = factories.make_incident(factories.open_work_item(choice_case, "count"))
    response = _resolve(engineer_client, incident, resolution="retry")
    assert response.status_code == 409
    assert "nothing to retry" in response.data["detail"]
