"""A cobot belongs to one organisation end to end: its gateway endpoint, its credentials,
the networks it may be on, and what a failed connection tells (issue 17, finding 2)."""

from __future__ import annotations

import ipaddress
import socket
import threading
from collections.abc import Iterator
from io import StringIO

import pytest
from django.contrib.auth.models import User
from django.core.exceptions import ValidationError
from django.core.management import CommandError, call_command
from django.db import IntegrityError, transaction
from django.test import Client, override_settings
from rest_framework.test import APIClient

from hrc.cobots import services
from hrc.cobots.credentials import credentials_for
from hrc.cobots.drivers.base import unreachable_message
from hrc.cobots.drivers.runner import driver_for_cobot
from hrc.cobots.models import Cobot, CredentialsSecret
from hrc.cobots.selectors import live_state
from hrc.cobots.simulated import free_port
from hrc.organisations.models import Organisation
from hrc_gateway.endpoints import endpoint_key
from tests import factories

# --- One gateway, one cobot ------------------------------------------------------------


@pytest.mark.parametrize(
    ("first", "second"),
    [
        ("opc.tcp://127.0.0.1:4941", "opc.tcp://localhost:4941"),
        ("opc.tcp://127.0.0.1:4941", "opc.tcp://[::ffff:127.0.0.1]:4941"),
        ("opc.tcp://localhost:4941", "opc.tcp://[::1]:4941"),
        ("opc.tcp://127.0.0.1:4941", "opc.tcp://127.0.0.2:4941"),
        ("opc.tcp://cobot.plant.local", "opc.tcp://COBOT.plant.local.:4840"),
        ("opc.tcp://10.0.0.5:4840/urua", "opc.tcp://10.0.0.5"),
        ("opc.tcp://[fd00::0:1]:4840", "opc.tcp://[fd00::1]"),
    ],
)
def test_spellings_of_one_gateway_share_one_key(first: str, second: str) -> None:
    assert endpoint_key(first) == endpoint_key(second)


def test_other_ports_and_hosts_are_other_gateways() -> None:
    assert endpoint_key("opc.tcp://127.0.0.1:4941") != endpoint_key("opc.tcp://127.0.0.1:4942")
    assert endpoint_key("opc.tcp://10.0.0.5") != endpoint_key("opc.tcp://10.0.0.6")


def test_a_second_cobot_of_the_organisation_at_the_gateway_is_refused_naming_the_first(
    organisation: Organisation,
) -> None:
    factories.make_cobot(organisation, name="cobot1", endpoint="opc.tcp://127.0.0.1:4941")
    with pytest.raises(ValidationError) as refused:
        factories.make_cobot(organisation, name="cobot2", endpoint="opc.tcp://localhost:4941")
    [message] = refused.value.message_dict["endpoint"]
    assert "already registered to cobot cobot1" in message


def test_moving_a_cobot_onto_a_taken_gateway_is_refused(organisation: Organisation) -> None:
    factories.make_cobot(organisation, name="cobot1", endpoint="opc.tcp://127.0.0.1:4941")
    second = factories.make_cobot(organisation, name="cobot2", endpoint="opc.tcp://127.0.0.1:4942")
    with pytest.raises(ValidationError, match="already registered to cobot cobot1"):
        services.update_cobot(second, endpoint="opc.tcp://[::ffff:127.0.0.1]:4941")
    second.refresh_from_db()
    assert second.endpoint == "opc.tcp://127.0.0.1:4942"


def test_the_database_holds_the_rule_when_the_check_is_raced(
    organisation: Organisation, other_organisation: Organisation
) -> None:
    # What a registration that passed clean() before the other committed would write.
    factories.make_cobot(organisation, endpoint="opc.tcp://127.0.0.1:4941")
    with pytest.raises(IntegrityError), transaction.atomic():
        Cobot(organisation=other_organisation, name="x", endpoint="opc.tcp://localhost:4941").save()


def test_a_raced_registration_is_told_why(
    organisation: Organisation, other_organisation: Organisation, monkeypatch: pytest.MonkeyPatch
) -> None:
    factories.make_cobot(organisation, name="cobot1", endpoint="opc.tcp://127.0.0.1:4941")
    checks = iter([False, True])  # the first check sees nothing yet; the re-check sees cobot1
    original = Cobot._endpoint_taken

    def racing(self: Cobot, key: str) -> str | None:
        return original(self, key) if next(checks) else None

    monkeypatch.setattr(Cobot, "_endpoint_taken", racing)
    with pytest.raises(ValidationError, match="another organisation"):
        factories.make_cobot(other_organisation, endpoint="opc.tcp://localhost:4941")


def test_the_page_refuses_a_taken_gateway_at_its_field(
    organisation: Organisation, engineer: User
) -> None:
    factories.make_cobot(organisation, name="cobot1", endpoint="opc.tcp://127.0.0.1:4941")
    client = Client()
    client.force_login(engineer)
    form = {"name": "cobot2", "driver": "simulated", "endpoint": "opc.tcp://localhost:4941",
            "credentials_source": "none", "cell": "", "is_active": "on"}  # fmt: skip
    response = client.post("/cobots/new/", form)
    assert response.status_code == 400
    assert "already registered to cobot cobot1" in response.content.decode()
    assert Cobot.objects.count() == 1


def test_the_django_admin_refuses_a_taken_gateway(
    staff_client: Client, organisation: Organisation, other_organisation: Organisation
) -> None:
    factories.make_cobot(organisation, name="cobot1", endpoint="opc.tcp://127.0.0.1:4941")
    data = {"organisation": str(other_organisation.pk), "name": "x", "is_active": "on",
            "driver": "simulated", "endpoint": "opc.tcp://[::ffff:127.0.0.1]:4941",
            "credentials_source": "none"}  # fmt: skip
    response = staff_client.post("/admin/cobots/cobot/add/", data)
    assert response.status_code == 200  # the form again, with the error
    assert "already registered to a cobot of another organisation" in response.content.decode()
    assert Cobot.objects.count() == 1


# --- Credentials: a named secret of the cobot's own organisation -------------------------


def test_a_secret_is_stored_encrypted_and_read_back_for_its_own_organisation_only(
    organisation: Organisation, other_organisation: Organisation
) -> None:
    # Not in the token's alphabet (base64url), so neither can turn up in it by chance, as
    # "p1" once did.
    user, password = "ours!", "pass word 1!"
    services.set_credentials_secret(organisation, "gw", username=user, password=password, by=None)
    services.set_credentials_secret(
        other_organisation, "gw", username="theirs", password="p2", by=None
    )
    sealed = CredentialsSecret.objects.get(organisation=organisation).sealed
    assert password not in sealed
    assert user not in sealed
    assert credentials_for("c", organisation.pk, "secret:gw") == (user, password)
    assert credentials_for("c", other_organisation.pk, "secret:gw") == ("theirs", "p2")


def test_a_cobot_cannot_name_another_organisations_secret(
    organisation: Organisation, other_organisation: Organisation
) -> None:
    services.set_credentials_secret(organisation, "home", username="u", password="p", by=None)
    with pytest.raises(ValidationError) as refused:
        factories.make_cobot(other_organisation, credentials_source="secret:home")
    assert "no credentials secret named home" in refused.value.message_dict["credentials_source"][0]


@pytest.mark.parametrize("source", ["env:COBOTS_CREDENTIALS", "file:/run/secrets/cobot1"])
def test_the_driver_refuses_an_older_env_or_file_source_without_reading_it(
    organisation: Organisation, monkeypatch: pytest.MonkeyPatch, source: str
) -> None:
    monkeypatch.setenv("COBOTS_CREDENTIALS", "hrc:hunter2")
    cobot = factories.make_cobot(organisation, endpoint=f"opc.tcp://127.0.0.1:{free_port()}")
    Cobot.objects.filter(pk=cobot.pk).update(credentials_source=source)  # a row from before
    cobot.refresh_from_db()
    state = live_state(cobot)
    assert state["reachable"] is False
    assert "create" in state["error"]
    assert "secret:NAME" in state["error"]
    assert "hunter2" not in state["error"]


def test_secrets_are_set_on_their_page_by_an_admin_and_never_shown_again(
    organisation: Organisation, admin: User, engineer: User
) -> None:
    client = Client()
    client.force_login(admin)
    form = {"name": "gw", "username": "hrc", "password": "hunter2"}
    assert client.post("/cobots/credentials/", form).status_code == 302
    page = client.get("/cobots/credentials/").content.decode()
    assert "secret:gw" in page
    assert "hunter2" not in page
    assert credentials_for("c", organisation.pk, "secret:gw") == ("hrc", "hunter2")
    client.force_login(engineer)
    assert client.get("/cobots/credentials/").status_code == 403


def test_a_secret_in_use_is_not_deleted(
    organisation: Organisation, admin_client: APIClient
) -> None:
    secret = services.set_credentials_secret(
        organisation, "gw", username="u", password="p", by=None
    )
    factories.make_cobot(organisation, name="cobot1", credentials_source="secret:gw")
    response = admin_client.delete(f"/api/cobot-credentials/{secret.pk}/")
    assert response.status_code == 400
    assert "cobot1" in response.data["detail"]
    assert CredentialsSecret.objects.filter(pk=secret.pk).exists()


def test_cobot_secret_sets_a_secret_from_the_environment(
    organisation: Organisation, monkeypatch: pytest.MonkeyPatch
) -> None:
    cobot = factories.make_cobot(organisation, name="cobot1")
    monkeypatch.setenv("GW_PASSWORD", "hunter2")
    out = StringIO()
    call_command(
        "cobot_secret", "gw", "--organisation", organisation.slug, "--user", "hrc",
        "--password-env", "GW_PASSWORD", "--cobot", "cobot1", stdout=out,
    )  # fmt: skip
    assert "secret gw set; used by cobot1" in out.getvalue()
    cobot.refresh_from_db()
    assert cobot.credentials_source == "secret:gw"
    assert credentials_for("c", organisation.pk, "secret:gw") == ("hrc", "hunter2")
    monkeypatch.delenv("GW_PASSWORD")
    with pytest.raises(CommandError, match="GW_PASSWORD is not set"):
        call_command("cobot_secret", "gw", "--organisation", organisation.slug,
                     "--user", "hrc", "--password-env", "GW_PASSWORD")  # fmt: skip


# --- HRC_COBOT_NETWORKS -------------------------------------------------------------------


@override_settings(HRC_COBOT_NETWORKS=[ipaddress.ip_network("10.20.0.0/16")])
def test_an_endpoint_outside_the_networks_is_refused_at_registration(
    organisation: Organisation,
) -> None:
    factories.make_cobot(organisation, endpoint="opc.tcp://10.20.1.2:4840")
    for outside in ("opc.tcp://127.0.0.1:5432", "opc.tcp://localhost:6379", "opc.tcp://10.21.0.1"):
        with pytest.raises(ValidationError, match="outside the networks"):
            factories.make_cobot(organisation, endpoint=outside)


@pytest.fixture
def listener() -> Iterator[tuple[int, list[socket.socket]]]:
    """A TCP port that accepts and records connections, and says nothing."""
    server = socket.create_server(("127.0.0.1", 0))
    accepted: list[socket.socket] = []

    def accept() -> None:
        while True:
            try:
                accepted.append(server.accept()[0])
            except OSError:
                return

    threading.Thread(target=accept, daemon=True).start()
    yield server.getsockname()[1], accepted
    server.close()
    for connection in accepted:
        connection.close()


def test_the_driver_never_connects_outside_the_networks(
    organisation: Organisation, listener: tuple[int, list[socket.socket]]
) -> None:
    port, accepted = listener
    cobot = factories.make_cobot(organisation, endpoint=f"opc.tcp://127.0.0.1:{port}")
    with override_settings(HRC_COBOT_NETWORKS=[ipaddress.ip_network("10.20.0.0/16")]):
        state = live_state(cobot, timeout=1.0)
    assert state["reachable"] is False
    assert "HRC_COBOT_NETWORKS" in state["error"]
    assert accepted == []


# --- No port oracle -------------------------------------------------------------------------


def test_a_failed_connection_reads_the_same_whatever_listens(
    organisation: Organisation,
    engineer_client: APIClient,
    listener: tuple[int, list[socket.socket]],
    caplog: pytest.LogCaptureFixture,
) -> None:
    silent_port, _ = listener
    closed_port = free_port()
    talker = socket.create_server(("127.0.0.1", 0))  # answers anything with HTTP, then hangs up

    def talk() -> None:
        while True:
            try:
                connection = talker.accept()[0]
            except OSError:
                return
            connection.sendall(b"HTTP/1.1 400 Bad Request\r\n\r\n")
            connection.close()

    threading.Thread(target=talk, daemon=True).start()
    errors = {}
    try:
        for port in (closed_port, silent_port, talker.getsockname()[1]):
            cobot = factories.make_cobot(organisation, endpoint=f"opc.tcp://127.0.0.1:{port}")
            driver_for_cobot(cobot, connect_timeout=1.0, request_timeout=1.0)
            state = engineer_client.get(f"/api/cobots/{cobot.pk}/state/").data
            errors[port] = (state["reachable"], state["error"].replace(cobot.name, "X"))
    finally:
        talker.close()
    assert set(errors.values()) == {(False, unreachable_message("X"))}
    assert "Cannot reach cobot" in caplog.text  # the detail went to the log
