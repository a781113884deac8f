"""Ids in API addresses are ASCII digits (hrc.api.routers); anything else is the API's JSON 404."""

import pytest
from rest_framework.test import APIClient

from hrc.cases.models import Case
from hrc.patterns.models import PatternModel

pytestmark = pytest.mark.django_db

# "²" and "٣" pass str.isdigit(); "²" fails int(), "٣" would be read as 3.
NOT_ASCII_IDS = ["%C2%B2", "%D9%A3", "1%C2%B2"]


@pytest.mark.parametrize("written", NOT_ASCII_IDS)
@pytest.mark.parametrize(
    ("method", "path"),
    [
        ("post", "/api/work-items/{}/claim/"),
        ("get", "/api/work-items/{}/"),
        ("get", "/api/cases/{}/events/"),
        ("get", "/api/patterns/{}/"),
        ("patch", "/api/cobots/{}/"),
        ("get", "/api/organisations/{}/"),
        ("delete", "/api/cells/{}/"),
    ],
)
def test_an_id_in_other_digits_than_ascii_is_a_json_404(
    engineer_client: APIClient, method: str, path: str, written: str
) -> None:
    response = getattr(engineer_client, method)(path.format(written), {}, format="json")
    assert response.status_code == 404
    assert response.json()["detail"].startswith("No API endpoint at")


def test_an_id_past_a_bigint_is_a_json_404(engineer_client: APIClient) -> None:
    response = engineer_client.get(f"/api/patterns/{'9' * 19}/")
    assert response.status_code == 404
    assert "detail" in response.json()


def test_ascii_ids_still_reach_their_objects(
    engineer_client: APIClient, pattern: PatternModel, choice_case: Case
) -> None:
    assert engineer_client.get(f"/api/patterns/{pattern.pk}/").status_code == 200
    assert engineer_client.get(f"/api/cases/{choice_case.pk}/events/").status_code == 200
