"""Devices of a cell: admins register, change and deactivate them (pages and API), members read
them over the API, and an outsider sees none of them anywhere."""

from __future__ import annotations

import pytest
from django.contrib.auth.models import User
from django.test import Client
from rest_framework.test import APIClient

from hrc.cases import services as case_services
from hrc.cobots import services
from hrc.cobots.models import Cobot, Device
from hrc.organisations.choices import Role
from hrc.organisations.models import Cell, Organisation
from tests import factories

pytestmark = pytest.mark.django_db


def _client(user: User) -> Client:
    client = Client()
    client.force_login(user)
    return client


@pytest.fixture
def cobot(organisation: Organisation) -> Cobot:
    return factories.make_cobot(organisation, name="left", cell="cell-a")


@pytest.fixture
def axis(organisation: Organisation, cobot: Cobot) -> Device:
    return services.create_device(
        organisation, name="axis1", kind="linear-axis", cell="cell-a", gateway=cobot
    )


# API -----------------------------------------------------------------------------------------


def test_an_admin_registers_a_device_over_the_api_and_members_read_it(
    admin_client: APIClient, operator_client: APIClient, cobot: Cobot
) -> None:
    body = {"name": "axis1", "kind": "linear-axis", "cell": "cell-b", "gateway": cobot.pk}
    created = admin_client.post("/api/devices/", body, format="json")
    assert created.status_code == 201, created.data
    assert created.data["kind"] == "linear-axis"
    assert Cell.objects.filter(organisation=cobot.organisation, name="cell-b").exists()

    listed = operator_client.get("/api/devices/").data["results"]
    assert [d["name"] for d in listed] == ["axis1"]
    changed = admin_client.patch(
        f"/api/devices/{created.data['id']}/", {"is_active": False}, format="json"
    )
    assert changed.status_code == 200
    assert Device.objects.get(name="axis1").is_active is False


def test_only_admins_write_devices(
    engineer_client: APIClient, operator_client: APIClient, cobot: Cobot, axis: Device
) -> None:
    body = {"name": "d2", "kind": "display", "cell": "cell-a", "gateway": cobot.pk}
    for client in (engineer_client, operator_client):
        assert client.post("/api/devices/", body, format="json").status_code == 403
        response = client.patch(f"/api/devices/{axis.pk}/", {"is_active": False}, format="json")
        assert response.status_code == 403
    assert Device.objects.get(pk=axis.pk).is_active


def test_bad_device_input_is_a_400_naming_the_field(admin_client: APIClient, cobot: Cobot) -> None:
    wrong_kind = {"name": "x", "kind": "teleporter", "cell": "cell-a", "gateway": cobot.pk}
    response = admin_client.post("/api/devices/", wrong_kind, format="json")
    assert response.status_code == 400
    assert "kind" in response.data["fields"]
    services.create_device(cobot.organisation, name="taken", kind="display", gateway=cobot)
    taken = {"name": "taken", "kind": "display", "cell": "", "gateway": cobot.pk}
    response = admin_client.post("/api/devices/", taken, format="json")
    assert response.status_code == 400
    assert "already has a device of this name" in str(response.data["fields"]["name"])


def test_an_outsider_neither_lists_nor_finds_nor_serves_our_devices(
    outsider_client: APIClient, other_organisation: Organisation, axis: Device, cobot: Cobot
) -> None:
    assert outsider_client.get("/api/devices/").data["results"] == []
    assert outsider_client.get(f"/api/devices/{axis.pk}/").status_code == 404
    assert (
        outsider_client.patch(
            f"/api/devices/{axis.pk}/", {"name": "mine"}, format="json"
        ).status_code
        == 404
    )
    # Nor may anyone's device be served through another organisation's cobot.
    outsider_admin = factories.make_member(other_organisation, Role.ADMIN)
    client = APIClient()
    client.force_authenticate(outsider_admin)
    body = {"name": "spy", "kind": "display", "cell": "", "gateway": cobot.pk}
    response = client.post("/api/devices/", body, format="json")
    assert response.status_code == 400
    assert "gateway" in response.data["fields"]
    assert not Device.objects.filter(name="spy").exists()


def test_the_model_refuses_a_gateway_of_another_organisation(
    other_organisation: Organisation, cobot: Cobot
) -> None:
    with pytest.raises(Exception, match="gateway"):
        services.create_device(other_organisation, name="d", kind="display", gateway=cobot)


# Pages ---------------------------------------------------------------------------------------


def test_an_admin_registers_edits_and_deactivates_a_device_on_the_pages(
    admin: User, cobot: Cobot
) -> None:
    client = _client(admin)
    assert client.get("/cobots/devices/new/").status_code == 200
    response = client.post(
        "/cobots/devices/new/",
        {"name": "cam1", "kind": "part-detection", "cell": "cell-a", "gateway": cobot.pk,
         "is_active": "on"},
    )  # fmt: skip
    assert response.status_code == 302
    device = Device.objects.get(name="cam1")
    assert (device.kind, device.cell, device.gateway_id) == ("part-detection", "cell-a", cobot.pk)

    page = client.get("/cobots/devices/").content.decode()
    assert "cam1" in page
    assert "Part detection" in page
    response = client.post(
        f"/cobots/devices/{device.pk}/edit/",
        {"name": "cam1", "kind": "part-detection", "cell": "cell-a", "gateway": cobot.pk},
    )
    assert response.status_code == 302
    device.refresh_from_db()
    assert device.is_active is False


def test_a_wrong_device_form_is_a_400_at_its_field(admin: User, cobot: Cobot, axis: Device) -> None:
    response = _client(admin).post(
        "/cobots/devices/new/",
        {"name": "axis1", "kind": "linear-axis", "cell": "cell-a", "gateway": cobot.pk},
    )
    assert response.status_code == 400
    assert "already has a device named axis1" in str(response.context["form"].errors["name"])


def test_the_device_pages_are_for_admins_and_outsiders_find_nothing(
    engineer: User, outsider: User, other_organisation: Organisation, axis: Device
) -> None:
    assert _client(engineer).get("/cobots/devices/").status_code == 403
    assert _client(engineer).get(f"/cobots/devices/{axis.pk}/edit/").status_code == 403
    outsider_admin = factories.make_member(other_organisation, Role.ADMIN)
    assert _client(outsider_admin).get(f"/cobots/devices/{axis.pk}/edit/").status_code == 404
    listed = _client(outsider_admin).get("/cobots/devices/").content.decode()
    assert "axis1" not in listed


def test_the_cobot_page_and_the_device_list_show_a_devices_queue(
    admin: User, operator: User, organisation: Organisation, cobot: Cobot, axis: Device
) -> None:
    version = factories.make_version(organisation, published_by=admin, draft=_axis_twice())
    case = case_services.start_case(version, started_by=admin, actor_mapping={})

    # The supervisor's case page: who has the call (the device) and where it stands.
    row = _client(admin).get(f"/cases/{case.pk}/").context["work_rows"][0]
    assert (row.who, row.job) == ("axis1", "queued, position 1")
    for path in ("/cobots/devices/", f"/cobots/{cobot.pk}/"):
        page = _client(admin).get(path).content.decode()
        assert "move left" in page, path
        assert "queued" in page


def _axis_twice() -> dict[str, object]:
    tasks = [
        {"id": "ta_left", "performer": "axis", "label": "move left", "task": {
            "device": {"call": "linear-axis.move", "args": {"direction": "left", "duration_ms": 0}}}},
    ]  # fmt: skip
    return {
        "format": "hrc-pattern/1",
        "name": "Axis",
        "actors": [
            {"id": "axis", "type": "cobot", "device": "linear-axis"},
        ],
        "processes": [{
            "id": "N", "workpiece": "w", "actors": ["axis"],
            "places": [{"id": "p0", "tokens": 1}, {"id": "p1", "tokens": 0}],
            "transitions": tasks, "arcs": [["p0", "ta_left"], ["ta_left", "p1"]],
        }],
        "constraints": [],
    }  # fmt: skip
