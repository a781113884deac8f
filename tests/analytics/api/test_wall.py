"""The analytics API behind the organisation wall: engineers and admins of the organisation
read it; its operators get 403; anyone else gets 404 (401 without credentials)."""

import pytest
from django.contrib.auth.models import User
from rest_framework.test import APIClient

from hrc.cases.models import Case
from hrc.cobots.models import Cobot
from hrc.organisations.models import Organisation
from hrc.patterns.models import PatternVersion
from tests import factories
from tests.analytics.running import run_hand_over

pytestmark = pytest.mark.django_db

ENDPOINTS = [
    "/api/analytics/versions/{version}/",
    "/api/analytics/cases/{case}/gantt/",
    "/api/analytics/xes/?version={version}",
    "/api/analytics/xes/?case={case}",
]


@pytest.fixture
def case(hand_over: PatternVersion, engineer: User, operator: User, cobot: Cobot) -> Case:
    return run_hand_over(hand_over, engineer, operator, cobot)


def ids(case: Case) -> dict[str, int]:
    return {"version": case.version_id, "case": case.pk}


@pytest.mark.parametrize("endpoint", ENDPOINTS)
@pytest.mark.parametrize("persona", ["engineer_client", "admin_client"])
def test_engineers_and_admins_of_the_organisation_read_its_analytics(
    endpoint: str, persona: str, case: Case, request: pytest.FixtureRequest
) -> None:
    client: APIClient = request.getfixturevalue(persona)
    assert client.get(endpoint.format(**ids(case))).status_code == 200


@pytest.mark.parametrize("endpoint", ENDPOINTS)
def test_an_operator_of_the_organisation_gets_403_with_the_reason(
    endpoint: str, case: Case, operator_client: APIClient
) -> None:
    response = operator_client.get(endpoint.format(**ids(case)))
    assert response.status_code == 403
    assert response.json()["detail"] == (
        "Only engineers and admins of the organisation see its analytics."
    )


@pytest.mark.parametrize("endpoint", ENDPOINTS)
@pytest.mark.parametrize("persona", ["outsider_client", "loner_client"])
def test_anyone_outside_the_organisation_gets_404_and_learns_nothing(
    endpoint: str, persona: str, case: Case, request: pytest.FixtureRequest
) -> None:
    client: APIClient = request.getfixturevalue(persona)
    response = client.get(endpoint.format(**ids(case)))
    assert response.status_code == 404
    assert case.version.pattern.name not in response.content.decode()


@pytest.mark.parametrize("endpoint", ENDPOINTS)
def test_the_outsider_reads_the_analytics_of_their_own_organisation(
    endpoint: str,
    outsider: User,
    outsider_client: APIClient,
    other_organisation: Organisation,
    case: Case,
) -> None:
    # The positive control: the 404s above are the wall, not a broken URL.
    version = factories.make_version(other_organisation, published_by=outsider)
    their_cobot = factories.make_cobot(other_organisation)
    theirs = run_hand_over(version, outsider, outsider, their_cobot)
    assert outsider_client.get(endpoint.format(**ids(theirs))).status_code == 200


@pytest.mark.parametrize("endpoint", ENDPOINTS)
def test_without_credentials_the_answer_is_401(
    endpoint: str, case: Case, anonymous_client: APIClient
) -> None:
    assert anonymous_client.get(endpoint.format(**ids(case))).status_code == 401


def test_a_case_of_another_organisation_inside_an_export_of_ours_is_a_404(
    engineer_client: APIClient,
    case: Case,
    outsider: User,
    other_organisation: Organisation,
) -> None:
    their_version = factories.make_version(other_organisation, published_by=outsider)
    theirs = run_hand_over(
        their_version, outsider, outsider, factories.make_cobot(other_organisation)
    )
    response = engineer_client.get(
        f"/api/analytics/xes/?version={case.version_id}&case={theirs.pk}"
    )
    assert response.status_code == 404


def test_the_schema_documents_the_analytics_endpoints(anonymous_client: APIClient) -> None:
    schema = anonymous_client.get("/api/schema/").content.decode()
    for path in ("/api/analytics/versions/{id}/", "/api/analytics/cases/{id}/gantt/",
                 "/api/analytics/xes/"):  # fmt: skip
        assert path in schema
    assert "application/xml" in schema
