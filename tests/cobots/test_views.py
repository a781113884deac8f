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
from hrc.cobots.gateway.launcher import GatewayProcess
from hrc.cobots.models import Cobot, CobotCommand
from hrc.organisations.models import Organisation
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
