"""Every endpoint against every persona: the organisation wall and the role rules.

An outsider (an engineer elsewhere) gets 404 for each of our objects and never
sees them in a list; an operator reads but gets 403 on every write; a request
without credentials gets 401; members get through (the positive control
that shows the 404s are the wall, not a broken URL).
"""

from dataclasses import dataclass
from typing import Any

import pytest
from django.contrib.auth.models import User
from rest_framework.test import APIClient

from hrc.cobots import services as cobot_services
from hrc.cobots.models import CellStop, Cobot, CobotCommand, CredentialsSecret
from hrc.organisations.models import Organisation
from hrc.patterns import services
from hrc.patterns.models import PatternModel, PatternVersion
from tests import factories


@dataclass(frozen=True)
class Endpoint:
    method: str
    path: str
    write: bool
    body: Any = None

    def call(self, client: APIClient, ids: dict[str, int]) -> Any:
        return getattr(client, self.method)(self.path.format(**ids), self.body, format="json")

    def __str__(self) -> str:
        return f"{self.method.upper()} {self.path}"


PATTERN_BODY = {"name": "Overwritten", "draft": factories.valid_document()}
COBOT_BODY = {"name": "overwritten", "driver": "simulated", "endpoint": "opc.tcp://x:4840"}

OBJECT_ENDPOINTS = [
    Endpoint("get", "/api/organisations/{organisation}/", write=False),
    Endpoint("get", "/api/patterns/{pattern}/", write=False),
    Endpoint("put", "/api/patterns/{pattern}/", write=True, body=PATTERN_BODY),
    Endpoint("patch", "/api/patterns/{pattern}/", write=True, body={"name": "Overwritten"}),
    Endpoint("delete", "/api/patterns/{pattern}/", write=True),
    # Changes nothing, but costs the engine: for the editors only, as writes are.
    Endpoint("post", "/api/patterns/{pattern}/check/", write=True),
    Endpoint("post", "/api/patterns/{pattern}/publish/", write=True),
    Endpoint("get", "/api/patterns/{pattern}/versions/", write=False),
    Endpoint("get", "/api/patterns/{pattern}/export/", write=False),
    Endpoint("get", "/api/patterns/{pattern}/export/?format=pnml", write=False),
    Endpoint("get", "/api/pattern-versions/{version}/", write=False),
    Endpoint("get", "/api/pattern-versions/{version}/export/", write=False),
    Endpoint(
        "put",
        "/api/pattern-versions/{version}/start-rights/",
        write=True,
        body={"roles": ["operator"], "cells": []},
    ),
    Endpoint("post", "/api/pattern-versions/{version}/retire/", write=True, body={"on": True}),
    Endpoint("post", "/api/patterns/{pattern}/archive/", write=True, body={"on": True}),
    Endpoint("get", "/api/cobots/{cobot}/", write=False),
    Endpoint("put", "/api/cobots/{cobot}/", write=True, body=COBOT_BODY),
    Endpoint("patch", "/api/cobots/{cobot}/", write=True, body={"name": "overwritten"}),
    Endpoint("delete", "/api/cobots/{cobot}/", write=True),
]
# A credentials secret: members read its name, only admins of its organisation write.
CREDENTIALS_ENDPOINTS = [
    Endpoint("get", "/api/cobot-credentials/{secret}/", write=False),
    Endpoint("delete", "/api/cobot-credentials/{secret}/", write=True),
]
SECRET_BODY = {"name": "home", "username": "mallory", "password": "borrowed"}
CONFIRMED = {"confirm": True}
# A person's control of a cobot (hrc.cobots.control): the wall and the role decide before
# the cobot is reached, so these need no gateway.
COBOT_CONTROL_ENDPOINTS = [
    *(
        Endpoint("post", f"/api/cobots/{{cobot}}/{action}/", write=True, body=CONFIRMED)
        for action in (
            "power-on",
            "brake-release",
            "power-off",
            "program/start",
            "program/pause",
            "program/stop",
        )
    ),
    Endpoint(
        "post", "/api/cobots/{cobot}/program/", write=True, body={"program": "x", "confirm": True}
    ),
    Endpoint("get", "/api/cobots/{cobot}/state/", write=False),
    Endpoint("get", "/api/cobots/{cobot}/registers/", write=False),
    Endpoint("get", "/api/cobots/{cobot}/registers/?names=Int24", write=False),
    Endpoint("get", "/api/cobots/{cobot}/programs/", write=False),
    Endpoint("get", "/api/cobots/{cobot}/commands/", write=False),
]
LIST_ENDPOINTS = [
    "/api/organisations/",
    "/api/patterns/",
    "/api/pattern-versions/",
    "/api/cobots/",
    "/api/cobot-credentials/",
]
CREATE_ENDPOINTS = [
    Endpoint("post", "/api/patterns/", write=True, body=PATTERN_BODY),
    Endpoint("post", "/api/patterns/import/", write=True, body=factories.valid_document()),
    Endpoint("post", "/api/cobots/", write=True, body=COBOT_BODY),
]
CELL_ENDPOINTS = [
    Endpoint("post", "/api/cells/stop/", write=False, body={"cell": "A"}),
    Endpoint("post", "/api/cells/resume/", write=False, body={"cell": "A", "confirm": True}),
]
ALL_ENDPOINTS = [
    *OBJECT_ENDPOINTS,
    *CREDENTIALS_ENDPOINTS,
    *CELL_ENDPOINTS,
    Endpoint("post", "/api/cobot-credentials/", write=True, body=SECRET_BODY),
    *COBOT_CONTROL_ENDPOINTS,
    *CREATE_ENDPOINTS,
    *(Endpoint("get", path, write=False) for path in LIST_ENDPOINTS),
    Endpoint("get", "/api/organisations/me/", write=False),
]


@dataclass
class World:
    """One of everything in the home organisation."""

    organisation: Organisation
    pattern: PatternModel
    version: PatternVersion
    cobot: Cobot
    secret: CredentialsSecret

    @property
    def ids(self) -> dict[str, int]:
        return {
            "organisation": self.organisation.pk,
            "pattern": self.pattern.pk,
            "version": self.version.pk,
            "cobot": self.cobot.pk,
            "secret": self.secret.pk,
        }

    def assert_untouched(self) -> None:
        self.pattern.refresh_from_db()
        self.cobot.refresh_from_db()
        assert self.pattern.name == "Hand-over"
        assert self.cobot.name == "cobot1"
        assert (self.cobot.endpoint, self.cobot.stopped_at) == (HOME_ENDPOINT, None)
        assert CredentialsSecret.objects.get(pk=self.secret.pk).sealed == self.secret.sealed
        assert not CellStop.objects.exists()
        assert list(self.pattern.versions.values_list("number", flat=True)) == [1]
        assert self.pattern.archived_at is None
        self.version.refresh_from_db()
        assert (self.version.retired_at, self.version.start_roles) == (None, ["admin", "engineer"])


HOME_ENDPOINT = "opc.tcp://127.0.0.1:4941"


@pytest.fixture
def world(organisation: Organisation, engineer: User) -> World:
    pattern = factories.make_pattern(organisation, name="Hand-over", created_by=engineer)
    version = services.publish_pattern(pattern, published_by=engineer)
    secret = cobot_services.set_credentials_secret(
        organisation, "home", username="hrc", password="hunter2", by=None
    )
    cobot = factories.make_cobot(
        organisation,
        name="cobot1",
        cell="A",
        endpoint=HOME_ENDPOINT,
        credentials_source="secret:home",
    )
    return World(organisation, pattern, version, cobot, secret)


@pytest.mark.parametrize(
    "endpoint", OBJECT_ENDPOINTS + COBOT_CONTROL_ENDPOINTS + CREDENTIALS_ENDPOINTS, ids=str
)
def test_an_outsider_gets_404_for_every_object_of_another_organisation(
    outsider_client: APIClient, world: World, endpoint: Endpoint
) -> None:
    assert endpoint.call(outsider_client, world.ids).status_code == 404
    world.assert_untouched()
    assert not CobotCommand.objects.exists()


@pytest.mark.parametrize("path", LIST_ENDPOINTS)
def test_an_outsider_sees_nothing_of_another_organisation_in_lists(
    outsider_client: APIClient, world: World, path: str
) -> None:
    response = outsider_client.get(path)
    assert response.status_code == 200
    if path == "/api/organisations/":  # the outsider's own organisation, and only that
        assert [o["name"] for o in response.data["results"]] == ["Other plant"]
    else:
        assert response.data["results"] == []


@pytest.mark.parametrize("path", LIST_ENDPOINTS)
def test_a_user_without_membership_sees_empty_lists(
    loner_client: APIClient, world: World, path: str
) -> None:
    response = loner_client.get(path)
    assert response.status_code == 200
    assert response.data["count"] == 0


@pytest.mark.parametrize(
    "endpoint",
    [e for e in OBJECT_ENDPOINTS + COBOT_CONTROL_ENDPOINTS + CREATE_ENDPOINTS if e.write],
    ids=str,
)
def test_an_operator_gets_403_on_every_write(
    operator_client: APIClient, world: World, endpoint: Endpoint
) -> None:
    response = endpoint.call(operator_client, world.ids)
    assert response.status_code == 403
    assert "engineers and admins" in response.data["detail"]
    world.assert_untouched()
    assert PatternModel.objects.count() == 1
    assert Cobot.objects.count() == 1
    assert not CobotCommand.objects.exists()


@pytest.mark.parametrize("endpoint", [e for e in OBJECT_ENDPOINTS if not e.write], ids=str)
def test_an_operator_reads_every_object_of_their_organisation(
    operator_client: APIClient, world: World, endpoint: Endpoint
) -> None:
    assert endpoint.call(operator_client, world.ids).status_code == 200


@pytest.mark.parametrize("path", LIST_ENDPOINTS)
def test_an_operator_lists_their_organisations_objects(
    operator_client: APIClient, world: World, path: str
) -> None:
    assert operator_client.get(path).data["count"] == 1


@pytest.mark.parametrize("endpoint", ALL_ENDPOINTS, ids=str)
def test_without_credentials_every_endpoint_is_refused(
    anonymous_client: APIClient, world: World, endpoint: Endpoint
) -> None:
    response = endpoint.call(anonymous_client, world.ids)

    assert response.status_code == 401
    assert response["WWW-Authenticate"] == "Token"
    world.assert_untouched()


@pytest.mark.parametrize(
    "endpoint",
    [e for e in OBJECT_ENDPOINTS if e.write and e.method != "delete"] + CREATE_ENDPOINTS,
    ids=str,
)
def test_an_engineer_writes_through_every_write_endpoint(
    engineer_client: APIClient, world: World, endpoint: Endpoint
) -> None:
    assert endpoint.call(engineer_client, world.ids).status_code in (200, 201)


# Cobots, cells and credentials by what they are named in a body, not by id in the URL.


@pytest.mark.parametrize(
    "endpoint",
    [
        "opc.tcp://127.0.0.1:4941",
        "opc.tcp://localhost:4941",
        "opc.tcp://LOCALHOST.:4941",
        "opc.tcp://[::ffff:127.0.0.1]:4941",
        "opc.tcp://[::1]:4941",
        "opc.tcp://127.1:4941",
        "opc.tcp://0.0.0.0:4941",
        "opc.tcp://127.0.0.1:4941/urua",
    ],
)
def test_an_outsider_cannot_register_our_gateway_under_any_spelling(
    outsider_client: APIClient, world: World, endpoint: str
) -> None:
    body = {"name": "borrowed", "driver": "simulated", "endpoint": endpoint}
    response = outsider_client.post("/api/cobots/", body, format="json")
    assert response.status_code == 400
    [message] = response.data["fields"]["endpoint"]
    assert "already registered to a cobot of another organisation" in message
    assert "cobot1" not in message  # our cobot's name stays behind the wall
    assert Cobot.objects.count() == 1
    world.assert_untouched()


def test_an_outsider_cannot_sign_in_with_our_credentials_secret(
    outsider_client: APIClient, world: World
) -> None:
    body = {
        "name": "borrowed",
        "driver": "simulated",
        "endpoint": "opc.tcp://10.9.9.9:4840",
        "credentials_source": "secret:home",
    }
    response = outsider_client.post("/api/cobots/", body, format="json")
    assert response.status_code == 400
    assert "no credentials secret named home" in response.data["fields"]["credentials_source"][0]
    assert Cobot.objects.count() == 1


@pytest.mark.parametrize("source", ["env:COBOTS_CREDENTIALS", "file:/run/secrets/cobot1"])
def test_nobody_signs_in_with_the_workers_environment_or_files(
    engineer_client: APIClient, world: World, source: str
) -> None:
    body = {**COBOT_BODY, "endpoint": "opc.tcp://10.9.9.9:4840", "credentials_source": source}
    response = engineer_client.post("/api/cobots/", body, format="json")
    assert response.status_code == 400
    assert "secret:NAME" in response.data["fields"]["credentials_source"][0]


@pytest.mark.parametrize(
    "body",
    [
        {"organisation": "{organisation}", "cell": "A"},
        {"cell": "A"},  # the outsider's own organisation has no cell A
        {"cell": ""},
        {},
    ],
    ids=["our cell by id", "a cell they lack", "empty cell", "no cell"],
)
@pytest.mark.parametrize("action", ["stop", "resume"])
def test_an_outsider_can_neither_stop_nor_resume_our_cobots(
    outsider_client: APIClient, world: World, body: dict[str, str], action: str
) -> None:
    body = {k: v.format(**world.ids) for k, v in body.items()}
    response = outsider_client.post(
        f"/api/cells/{action}/", {**body, "confirm": True}, format="json"
    )
    assert response.status_code == 400
    world.assert_untouched()


def test_an_outsider_cannot_set_a_secret_in_our_organisation(
    outsider_client: APIClient, world: World
) -> None:
    body = {**SECRET_BODY, "organisation": world.organisation.pk}
    response = outsider_client.post("/api/cobot-credentials/", body, format="json")
    assert response.status_code == 400
    assert "not a member" in str(response.data["fields"]["organisation"])
    world.assert_untouched()


@pytest.mark.parametrize("persona", ["operator_client", "engineer_client"])
def test_only_an_admin_sets_or_deletes_a_credentials_secret(
    request: pytest.FixtureRequest, admin_client: APIClient, world: World, persona: str
) -> None:
    client: APIClient = request.getfixturevalue(persona)
    assert client.get(f"/api/cobot-credentials/{world.secret.pk}/").status_code == 200
    for endpoint in [e for e in CREDENTIALS_ENDPOINTS if e.write]:
        response = endpoint.call(client, world.ids)
        assert response.status_code == 403
        assert "admins" in response.data["detail"]
    created = client.post("/api/cobot-credentials/", SECRET_BODY, format="json")
    assert created.status_code == 403
    world.assert_untouched()
    # The positive control: the admin replaces it, and no answer holds the password.
    replaced = admin_client.post("/api/cobot-credentials/", SECRET_BODY, format="json")
    assert replaced.status_code == 200
    assert "borrowed" not in str(replaced.data)
    assert "mallory" not in str(replaced.data)
