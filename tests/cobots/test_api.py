from typing import Any

import pytest
from rest_framework.test import APIClient

from hrc.cobots.models import Cobot
from hrc.organisations.models import Organisation
from tests import factories


@pytest.fixture
def cobot(organisation: Organisation) -> Cobot:
    return factories.make_cobot(organisation, name="cobot1")


NEW_COBOT: dict[str, Any] = {
    "name": "cobot9",
    "driver": "ur",
    "endpoint": "opc.tcp://ur10.plant.local:4840",
    "credentials_source": "none",
}


def test_members_read_their_organisations_cobots(operator_client: APIClient, cobot: Cobot) -> None:
    response = operator_client.get("/api/cobots/")
    assert [c["name"] for c in response.data["results"]] == ["cobot1"]
    detail = operator_client.get(f"/api/cobots/{cobot.pk}/").data
    assert detail["endpoint"] == cobot.endpoint
    assert detail["credentials_source"] == "none"


def test_an_outsider_neither_lists_nor_finds_our_cobots(
    outsider_client: APIClient, cobot: Cobot, other_organisation: Organisation
) -> None:
    factories.make_cobot(other_organisation, name="theirs")
    listed = outsider_client.get("/api/cobots/").data["results"]
    assert [c["name"] for c in listed] == ["theirs"]
    assert outsider_client.get(f"/api/cobots/{cobot.pk}/").status_code == 404


@pytest.mark.parametrize("client_name", ["engineer_client", "admin_client"])
def test_engineers_and_admins_register_cobots(
    request: pytest.FixtureRequest, client_name: str, organisation: Organisation
) -> None:
    client: APIClient = request.getfixturevalue(client_name)
    response = client.post("/api/cobots/", NEW_COBOT, format="json")
    assert response.status_code == 201, response.data
    assert Cobot.objects.get(pk=response.data["id"]).organisation == organisation


def test_an_operator_may_not_register_change_or_delete_a_cobot(
    operator_client: APIClient, cobot: Cobot
) -> None:
    assert operator_client.post("/api/cobots/", NEW_COBOT, format="json").status_code == 403
    url = f"/api/cobots/{cobot.pk}/"
    assert operator_client.patch(url, {"is_active": False}, format="json").status_code == 403
    assert operator_client.delete(url).status_code == 403
    cobot.refresh_from_db()
    assert cobot.is_active


def test_an_outsider_cannot_register_a_cobot_in_our_organisation(
    outsider_client: APIClient, organisation: Organisation
) -> None:
    body = {**NEW_COBOT, "organisation": organisation.pk}
    response = outsider_client.post("/api/cobots/", body, format="json")
    assert response.status_code == 400
    assert not organisation.cobots.exists()


def test_a_secret_typed_as_credentials_source_is_refused(engineer_client: APIClient) -> None:
    body = {**NEW_COBOT, "credentials_source": "my-password"}
    response = engineer_client.post("/api/cobots/", body, format="json")
    assert response.status_code == 400
    assert "credentials_source" in response.data["fields"]
    assert not Cobot.objects.exists()


def test_a_taken_name_is_a_400_not_a_500(engineer_client: APIClient, cobot: Cobot) -> None:
    response = engineer_client.post("/api/cobots/", {**NEW_COBOT, "name": "cobot1"}, format="json")
    assert response.status_code == 400
    assert "already has a cobot of this name" in response.data["detail"]


def test_an_engineer_changes_and_deletes_a_cobot(engineer_client: APIClient, cobot: Cobot) -> None:
    url = f"/api/cobots/{cobot.pk}/"
    response = engineer_client.patch(url, {"is_active": False}, format="json")
    assert response.status_code == 200
    cobot.refresh_from_db()
    assert not cobot.is_active
    assert engineer_client.delete(url).status_code == 204
    assert not Cobot.objects.filter(pk=cobot.pk).exists()


def test_a_cobot_cannot_move_to_another_organisation(
    admin_client: APIClient, cobot: Cobot, admin: Any, other_organisation: Organisation
) -> None:
    from hrc.organisations import services

    services.add_member(other_organisation, admin, "admin")
    url = f"/api/cobots/{cobot.pk}/"
    response = admin_client.patch(url, {"organisation": other_organisation.pk}, format="json")
    assert response.status_code == 400
    cobot.refresh_from_db()
    assert cobot.organisation_id != other_organisation.pk
