from django.test import Client

from hrc.cobots import services
from hrc.cobots.drivers.base import unreachable_message
from hrc.cobots.models import Cobot
from hrc.cobots.simulated import GatewayProcess, free_port
from hrc.organisations.models import Organisation
from tests import factories


def test_cobot_pages_render(staff_client: Client, organisation: Organisation) -> None:
    cobot = factories.make_cobot(organisation)
    for url in [
        "/admin/cobots/cobot/",
        "/admin/cobots/cobot/add/",
        f"/admin/cobots/cobot/{cobot.pk}/change/",
        "/admin/cobots/cobot/?driver__exact=simulated",
        "/admin/cobots/cobot/?q=cobot",
    ]:
        assert staff_client.get(url).status_code == 200, url


def test_the_add_page_explains_where_credentials_come_from(staff_client: Client) -> None:
    page = staff_client.get("/admin/cobots/cobot/add/").content.decode()
    assert "Never type the secret itself here" in page


def test_the_admin_registers_a_cobot(staff_client: Client, organisation: Organisation) -> None:
    services.set_credentials_secret(
        organisation, "ur10", username="hrc", password="hunter2", by=None
    )
    data = {
        "organisation": str(organisation.pk),
        "name": "ur10",
        "is_active": "on",
        "driver": "ur",
        "endpoint": "opc.tcp://ur10:4840",
        "credentials_source": "secret:ur10",
    }
    response = staff_client.post("/admin/cobots/cobot/add/", data)
    assert response.status_code == 302, response.content.decode()[:3000]
    assert Cobot.objects.get(name="ur10").credentials_source == "secret:ur10"


def test_the_admin_refuses_a_secret_as_credentials_source(
    staff_client: Client, organisation: Organisation
) -> None:
    data = {
        "organisation": str(organisation.pk),
        "name": "ur10",
        "driver": "ur",
        "endpoint": "opc.tcp://ur10:4840",
        "credentials_source": "hunter2",
    }
    response = staff_client.post("/admin/cobots/cobot/add/", data)
    assert response.status_code == 200
    assert not Cobot.objects.exists()


def test_the_change_page_tests_the_connection_and_shows_live_state(
    staff_client: Client, organisation: Organisation, gateway: GatewayProcess
) -> None:
    cobot = factories.make_cobot(organisation, name="cobot1", endpoint=gateway.endpoint)
    page = staff_client.get(f"/admin/cobots/cobot/{cobot.pk}/change/").content.decode()
    assert "Live state" in page
    assert "Test connection" in page
    state = staff_client.get(f"/admin/cobots/cobot/{cobot.pk}/state/").json()
    assert state["reachable"] is True
    assert state["RobotMode"] == "Power Off"
    response = staff_client.post(f"/admin/cobots/cobot/{cobot.pk}/test-connection/", follow=True)
    page = response.content.decode()
    assert "answered. RobotMode: Power Off" in page


def test_the_connection_test_says_why_a_cobot_does_not_answer(
    staff_client: Client, organisation: Organisation
) -> None:
    cobot = factories.make_cobot(organisation, endpoint=f"opc.tcp://127.0.0.1:{free_port()}")
    state = staff_client.get(f"/admin/cobots/cobot/{cobot.pk}/state/").json()
    assert state["reachable"] is False
    assert state["error"] == unreachable_message(cobot.name)
    response = staff_client.post(f"/admin/cobots/cobot/{cobot.pk}/test-connection/", follow=True)
    assert "did not answer" in response.content.decode()


def test_the_live_state_is_for_staff_only(client: Client, organisation: Organisation) -> None:
    cobot = factories.make_cobot(organisation)
    response = client.get(f"/admin/cobots/cobot/{cobot.pk}/state/")
    assert response.status_code == 302
    assert "/admin/login/" in response["Location"]
