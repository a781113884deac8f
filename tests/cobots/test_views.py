"""The cobot pages over HTTP: who may see them, and what they show of a real simulated cobot.

The buttons are the page script's confirmed POSTs to the API
(tests/cobots/test_control.py); the browser test (tests/browser/test_cobots.py)
presses one.
"""

from __future__ import annotations

import pytest
from django.contrib.auth.models import User
from django.test import Client

from hrc.cases import jobs
from hrc.cobots.models import Cobot, CobotCommand
from hrc.cobots.simulated import GatewayProcess
from hrc.organisations.models import AdminRecord, Cell, Organisation
from tests import factories
from tests.cobots.simulator import PROGRAM

pytestmark = pytest.mark.django_db


def _client(user: User) -> Client:
    client = Client()
    client.force_login(user)
    return client


@pytest.fixture
def cobot(organisation: Organisation, gateway: GatewayProcess) -> Cobot:
    return factories.make_cobot(organisation, name="cobot1", endpoint=gateway.endpoint, cell="A")


def test_an_engineer_sees_the_cobots_with_cell_state_and_queue(
    engineer: User, operator: User, organisation: Organisation, cobot: Cobot
) -> None:
    version = factories.make_version(organisation, published_by=engineer)
    factories.hand_over_case(version, started_by=engineer, operator=operator, cobot=cobot)

    response = _client(engineer).get("/cobots/")

    assert response.status_code == 200
    row = response.content.decode().split(f'data-cobot="{cobot.pk}"')[1].split("</tr>")[0]
    assert "cobot1" in row
    assert "<td>A</td>" in row
    assert "Power Off" in row
    assert '<td class="count nonzero">1</td>' in row


def test_the_cobot_page_shows_state_buttons_programs_registers_and_the_record(
    admin: User, cobot: Cobot
) -> None:
    CobotCommand.objects.create(
        cobot=cobot, command="power-on", requested_by=admin, outcome="refused", message="no"
    )

    response = _client(admin).get(f"/cobots/{cobot.pk}/")

    assert response.status_code == 200
    page = response.content.decode()
    assert 'data-field="RobotMode">Power Off<' in page
    for command in ("power-on", "brake-release", "power-off", "load-program", "program/stop"):
        assert f'data-path="{command}"' in page or f'data-command="{command}"' in page
    assert f'<option value="{PROGRAM}"' in page
    assert '<tr data-register="Int24"><td>Int24</td><td data-direction="inputs">0</td>' in page
    assert '<tr data-register="Bit127">' in page
    assert f"<td>{admin.username}</td>" in page
    assert 'class="outcome-refused">Refused<' in page
    assert "hrc/cobots.js" in page
    assert "Cobots</a>" in page  # the supervisor pages' header links here


def test_an_operator_is_refused_with_403_and_a_message(operator: User, cobot: Cobot) -> None:
    for url in ("/cobots/", f"/cobots/{cobot.pk}/"):
        response = _client(operator).get(url)
        assert response.status_code == 403
        assert "engineers and admins" in response.content.decode()


def test_an_outsider_gets_404_for_our_cobot_and_none_in_their_list(
    outsider: User, cobot: Cobot
) -> None:
    assert _client(outsider).get(f"/cobots/{cobot.pk}/").status_code == 404
    listing = _client(outsider).get("/cobots/")
    assert listing.status_code == 200
    assert "cobot1" not in listing.content.decode()


def test_a_visitor_who_is_not_signed_in_is_sent_to_sign_in(cobot: Cobot) -> None:
    response = Client().get(f"/cobots/{cobot.pk}/")
    assert response.status_code == 302
    assert response["Location"].startswith("/accounts/login/?next=")


def test_an_unreachable_cobot_page_says_so_instead_of_failing(
    engineer: User, organisation: Organisation
) -> None:
    cobot = factories.make_cobot(organisation, endpoint="opc.tcp://127.0.0.1:9")

    response = _client(engineer).get(f"/cobots/{cobot.pk}/")

    assert response.status_code == 200
    assert "unreachable" in response.content.decode()
    assert "Not read." in response.content.decode()


def test_the_list_counts_only_the_queue_of_each_cobot(
    engineer: User, operator: User, organisation: Organisation, cobot: Cobot
) -> None:
    version = factories.make_version(organisation, published_by=engineer)
    factories.hand_over_case(version, started_by=engineer, operator=operator, cobot=cobot)
    assert jobs.lease_next_job(cobot.pk) is not None  # running counts as queued

    other = factories.make_cobot(organisation, endpoint="opc.tcp://127.0.0.1:9")
    page = _client(engineer).get("/cobots/").content.decode()

    assert '<td class="count nonzero">1</td>' in page.split(f'data-cobot="{cobot.pk}"')[1]
    assert '<td class="count">0</td>' in page.split(f'data-cobot="{other.pk}"')[1]


# Registering and editing ---------------------------------------------------------


def _cobot_form(**changes: object) -> dict[str, object]:
    return {
        "name": "cobot9", "driver": "simulated", "endpoint": "opc.tcp://127.0.0.1:4899",
        "credentials_source": "none", "cell": "", "is_active": "on",
    } | changes  # fmt: skip


def test_an_engineer_registers_a_cobot_in_one_of_the_organisations_cells(
    engineer: User, organisation: Organisation
) -> None:
    Cell.objects.create(organisation=organisation, name="weld")
    response = _client(engineer).post("/cobots/new/", _cobot_form(cell="weld"))
    assert response.status_code == 302
    cobot = Cobot.objects.get(name="cobot9")
    assert cobot.organisation == organisation
    assert cobot.cell == "weld"
    assert AdminRecord.objects.filter(target="cobot9", actor=engineer).exists()


def test_another_organisations_cell_is_refused_at_the_field(
    engineer: User, other_organisation: Organisation
) -> None:
    Cell.objects.create(organisation=other_organisation, name="theirs")
    response = _client(engineer).post("/cobots/new/", _cobot_form(cell="theirs"))
    assert response.status_code == 400
    assert "id_cell-errors" in response.content.decode()
    assert not Cobot.objects.exists()


def test_a_taken_name_and_a_bad_endpoint_are_refused_at_their_fields(
    engineer: User, organisation: Organisation
) -> None:
    factories.make_cobot(organisation, name="cobot9")
    response = _client(engineer).post("/cobots/new/", _cobot_form(endpoint="http://x"))
    text = response.content.decode()
    assert response.status_code == 400
    assert "id_name-errors" in text
    assert "id_endpoint-errors" in text
    assert Cobot.objects.count() == 1


def test_an_engineer_edits_a_cobot_and_tests_its_connection(
    engineer: User, organisation: Organisation
) -> None:
    cobot = factories.make_cobot(organisation, name="cobot9", endpoint="opc.tcp://127.0.0.1:9")
    client = _client(engineer)
    response = client.post(f"/cobots/{cobot.pk}/edit/", _cobot_form(name="renamed"))
    assert response.status_code == 302
    cobot.refresh_from_db()
    assert cobot.name == "renamed"
    tested = client.post(f"/cobots/{cobot.pk}/edit/", {"test": "1"})
    assert tested.status_code == 200
    assert "did not answer" in tested.content.decode()


def test_operators_are_refused_and_outsiders_find_no_cobot_to_edit(
    operator: User, outsider: User, organisation: Organisation
) -> None:
    cobot = factories.make_cobot(organisation, name="cobot9")
    assert _client(operator).post("/cobots/new/", _cobot_form(name="x")).status_code == 403
    assert _client(operator).get(f"/cobots/{cobot.pk}/edit/").status_code == 403
    assert _client(outsider).get(f"/cobots/{cobot.pk}/edit/").status_code == 404
    assert _client(outsider).post(f"/cobots/{cobot.pk}/edit/", _cobot_form(name="y")).status_code == 404  # fmt: skip
    cobot.refresh_from_db()
    assert cobot.name == "cobot9"
    assert Cobot.objects.count() == 1
