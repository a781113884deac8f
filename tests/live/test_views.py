"""The tablet page over HTTP: a cell that does not exist, and starting a cycle at a cell.

The browser tests (tests/browser/test_tablet.py) do what the script does.
"""

import pytest
from django.contrib.auth.models import User
from django.test import Client

from hrc.cases import services as case_services
from hrc.cases.models import Case
from hrc.cobots.models import Cobot
from hrc.organisations.models import Organisation
from hrc.organisations.services import ensure_cell
from hrc.patterns.models import PatternVersion
from hrc.patterns.services import retire_version, set_start_rights
from tests import factories

pytestmark = pytest.mark.django_db


def _client(user: User) -> Client:
    client = Client()
    client.force_login(user)
    return client


@pytest.fixture
def version(
    organisation: Organisation, engineer: User, operator: User, cobot: Cobot
) -> PatternVersion:
    """The hand-over pattern, startable by operators at cell-a, with a whole number to start with."""
    document = factories.valid_document()
    document["data"] = {"batch": 1}
    version = factories.make_version(organisation, published_by=engineer, draft=document)
    case_services.set_default_actor_mapping(
        version, {"o": {"users": [operator.pk]}, "c": {"cobot": cobot.pk}}
    )
    ensure_cell(organisation, "cell-a")
    ensure_cell(organisation, "cell-b")
    return set_start_rights(version, roles=["engineer", "operator"], cells=["cell-a"])


def test_an_unknown_cell_says_so_and_lists_the_cells_without_a_stop(
    operator: User, organisation: Organisation
) -> None:
    ensure_cell(organisation, "cell-a")
    response = _client(operator).get("/tablet/cell1/")
    assert response.status_code == 404
    html = response.content.decode()
    assert "There is no cell “cell1” in" in html
    assert 'href="/tablet/cell-a/"' in html
    assert 'class="stop"' not in html


def test_a_cell_of_another_organisation_is_unknown_here(
    operator: User, other_organisation: Organisation
) -> None:
    ensure_cell(other_organisation, "their-cell")
    response = _client(operator).get("/tablet/their-cell/")
    assert response.status_code == 404
    assert "their-cell" not in response.content.decode().split("</h1>", 1)[1]


def test_the_start_cell_offers_the_version_and_the_operator_starts_a_cycle(
    operator: User, version: PatternVersion
) -> None:
    client = _client(operator)
    page = client.get("/tablet/cell-a/").content.decode()
    assert "Start a cycle" in page
    assert f"/tablet/cell-a/start/{version.pk}/" in page
    assert "Start a cycle" not in client.get("/tablet/cell-b/").content.decode()

    form = {f"v{version.pk}-reference": "W-9", f"v{version.pk}-data__batch": "3"}
    response = client.post(f"/tablet/cell-a/start/{version.pk}/", form)
    assert response.status_code == 302
    case = Case.objects.get()
    assert (case.reference, case.data["batch"], case.started_by) == ("W-9", 3, operator)
    assert f"started={case.pk}" in response["Location"]


def test_bad_start_data_is_shown_at_its_field_and_starts_nothing(
    operator: User, version: PatternVersion
) -> None:
    response = _client(operator).post(
        f"/tablet/cell-a/start/{version.pk}/", {f"v{version.pk}-data__batch": "three"}
    )
    assert response.status_code == 400
    assert "Enter a whole number." in response.content.decode()
    assert not Case.objects.exists()


@pytest.mark.parametrize("cell", ["cell-b", "nowhere"])
def test_no_cycle_starts_at_a_cell_the_version_does_not_name(
    operator: User, version: PatternVersion, cell: str
) -> None:
    response = _client(operator).post(f"/tablet/{cell}/start/{version.pk}/", {})
    assert response.status_code == 404
    assert not Case.objects.exists()


def test_a_retired_version_or_an_outsider_starts_nothing(
    operator: User, outsider: User, version: PatternVersion
) -> None:
    assert _client(outsider).post(f"/tablet/cell-a/start/{version.pk}/", {}).status_code == 404
    retire_version(version, retired=True)
    assert _client(operator).post(f"/tablet/cell-a/start/{version.pk}/", {}).status_code == 404
    assert "Start a cycle" not in _client(operator).get("/tablet/cell-a/").content.decode()
    assert not Case.objects.exists()
