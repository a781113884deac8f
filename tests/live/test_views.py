"""The tablet page: a cell the organisation has, and one it does not."""

from __future__ import annotations

import pytest
from django.contrib.auth.models import User
from django.test import Client

from hrc.organisations import services as organisation_services
from hrc.organisations.models import Organisation
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
