"""Lists page with `?limit=` and `?offset=`, checked before a query runs (hrc.api.pagination)."""

import pytest
from rest_framework.test import APIClient

from hrc.api.pagination import MAX_LIMIT, MAX_OFFSET
from hrc.organisations.models import Organisation
from tests import factories

pytestmark = pytest.mark.django_db


@pytest.fixture
def three_patterns(organisation: Organisation) -> None:
    for name in ("First", "Second", "Third"):
        factories.make_pattern(organisation, name=name)


def test_a_limit_past_a_bigint_is_cut_to_the_largest_page(
    engineer_client: APIClient, three_patterns: None
) -> None:
    response = engineer_client.get("/api/patterns/?limit=9223372036854775808")
    assert response.status_code == 200
    assert response.data["count"] == 3
    assert len(response.data["results"]) == 3


def test_a_limit_of_thousands_of_digits_is_cut_too(engineer_client: APIClient) -> None:
    assert engineer_client.get(f"/api/patterns/?limit={'9' * 5000}").status_code == 200


def test_a_limit_and_offset_page_through_the_list(
    engineer_client: APIClient, three_patterns: None
) -> None:
    response = engineer_client.get("/api/patterns/?limit=2&offset=1")
    assert response.status_code == 200
    assert len(response.data["results"]) == 2
    assert "limit=2" in response.data["previous"]


def test_without_a_limit_a_page_is_page_size_long(
    engineer_client: APIClient, organisation: Organisation
) -> None:
    for number in range(52):
        factories.make_pattern(organisation, name=f"Pattern {number}")
    response = engineer_client.get("/api/patterns/")
    assert len(response.data["results"]) == 50
    assert "limit=50" in response.data["next"]


def test_the_schema_states_the_bounds(anonymous_client: APIClient) -> None:
    schema = anonymous_client.get("/api/schema/?format=json").json()
    parameters = {
        p["name"]: p["schema"] for p in schema["paths"]["/api/patterns/"]["get"]["parameters"]
    }
    assert parameters["limit"]["minimum"] == 1
    assert parameters["offset"]["maximum"] == MAX_OFFSET
    assert MAX_LIMIT >= 1000  # the demo asks for every pattern with ?limit=1000


@pytest.mark.parametrize(
    ("query", "named"),
    [
        ("limit=%C2%B2", "limit"),  # a superscript two: str.isdigit() says yes, int() no
        ("limit=%D9%A3", "limit"),  # an Arabic-Indic three: int() reads it
        ("limit=0", "limit"),
        ("limit=-1", "limit"),
        ("limit=ten", "limit"),
        ("limit=", "limit"),
        ("offset=-1", "offset"),
        ("offset=%C2%B2", "offset"),
        (f"offset={MAX_OFFSET + 1}", "offset"),
        ("offset=9223372036854775808", "offset"),
    ],
)
def test_a_limit_or_offset_that_is_no_whole_number_in_range_is_a_400_naming_it(
    engineer_client: APIClient, query: str, named: str
) -> None:
    response = engineer_client.get(f"/api/patterns/?{query}")
    assert response.status_code == 400
    assert response.json()["detail"].startswith(f"{named} must be")
