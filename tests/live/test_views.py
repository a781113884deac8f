"""The tablet page: a cell the organisation has, one it does not, and starting a cycle at a cell."""

from __future__ import annotations

import pytest
from django.contrib.auth.models import User
from django.test import Client

from hrc.cases import services as case_services
from hrc.cases.models import Case
from hrc.cobots.models import Cobot
from hrc.organisations import services as organisation_services
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


def test_a_cells_tablet_loads_the_live_page(organisation: Organisation, operator: User) -> None:
    factories.make_cobot(organisation, cell="weld")
    response = _client(operator).get("/tablet/weld/")
    assert response.status_code == 200
    assert b'aria-label="STOP every cobot of the cell"' in response.content


def test_the_whole_floors_tablet_has_no_stop_and_sends_people_to_each_cells(
    organisation: Organisation, operator: User
) -> None:
    # A STOP names its cell: a button here could only be refused.
    factories.make_cobot(organisation, cell="weld")
    page = _client(operator).get("/tablet/").content.decode()
    assert 'class="stop"' not in page
    assert "STOP is on each cell's tablet" in page
    assert f'href="/tablet/weld/?organisation={organisation.pk}"' in page


def test_an_unknown_cell_says_so_and_lists_the_organisations_cells_with_no_stop(
    organisation: Organisation, other_organisation: Organisation, operator: User
) -> None:
    organisation_services.ensure_cell(organisation, "weld")
    organisation_services.ensure_cell(organisation, "paint")
    organisation_services.ensure_cell(other_organisation, "cell1")  # theirs, not ours

    response = _client(operator).get("/tablet/cell1/")

    assert response.status_code == 404
    page = response.content.decode()
    assert f"There is no cell 'cell1' in {organisation.name}" in page
    assert [cell.name for cell in response.context["cells"]] == ["paint", "weld"]
    assert 'href="/tablet/paint/"' in page
    assert 'href="/tablet/weld/"' in page
    assert "STOP" not in page
    assert "tablet.js" not in page  # no socket, nothing that looks live


def test_an_outsiders_cells_are_not_listed_to_them_nor_ours_to_them(
    organisation: Organisation, outsider: User
) -> None:
    organisation_services.ensure_cell(organisation, "weld")
    response = _client(outsider).get("/tablet/weld/")
    assert response.status_code == 404
    assert "weld" not in [cell.name for cell in response.context["cells"]]
    assert 'href="/tablet/weld/"' not in response.content.decode()


# Starting a cycle at a cell -------------------------------------------------------------


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


@pytest.mark.parametrize("written", ["%C2%B2", "%D9%A2"])  # "²" and "٢": isdigit() says yes
def test_a_tablet_asked_for_an_organisation_in_other_digits_than_ascii_is_refused(
    operator: User, written: str
) -> None:
    response = _client(operator).get(f"/tablet/?organisation={written}")
    assert response.status_code == 403
