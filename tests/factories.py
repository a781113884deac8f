"""Test data in one place: people, organisations, cobots, patterns and pattern documents.

Plain functions (no factory library): each makes a valid object with unique
names unless told otherwise, through the services where a service exists.
"""

import copy
import itertools
from typing import Any

from django.contrib.auth.models import User

from hrc.cobots import services as cobot_services
from hrc.cobots.choices import DriverKind
from hrc.cobots.models import Cobot
from hrc.organisations import services as organisation_services
from hrc.organisations.choices import Role
from hrc.organisations.models import Organisation
from hrc.patterns import services as pattern_services
from hrc.patterns.models import PatternModel

_serial = itertools.count(1)

PASSWORD = "a-test-password"


def make_user(username: str | None = None) -> User:
    return organisation_services.provision_user(
        username or f"user{next(_serial)}", password=PASSWORD
    )


def make_organisation(name: str | None = None) -> Organisation:
    number = next(_serial)
    return organisation_services.create_organisation(
        name=name or f"Plant {number}", slug=f"plant-{number}"
    )


def make_member(organisation: Organisation, role: Role, username: str | None = None) -> User:
    user = make_user(username)
    organisation_services.add_member(organisation, user, role)
    return user


def make_cobot(organisation: Organisation, **fields: Any) -> Cobot:
    number = next(_serial)
    values: dict[str, Any] = {
        "name": f"cobot{number}",
        "driver": DriverKind.SIMULATED,
        "endpoint": f"opc.tcp://sim-cobot{number}:4840",
    }
    return cobot_services.create_cobot(organisation, **(values | fields))


def make_pattern(
    organisation: Organisation,
    *,
    draft: object = None,
    name: str | None = None,
    created_by: User | None = None,
) -> PatternModel:
    return pattern_services.create_pattern(
        organisation,
        name=name or f"Pattern {next(_serial)}",
        created_by=created_by,
        draft=valid_document() if draft is None else draft,
    )


_HAND_OVER: dict[str, Any] = {
    "format": "hrc-pattern/1",
    "name": "Hand-over (1 operator, 1 cobot)",
    "declared_pattern": "synchronized",
    "actors": [{"id": "c", "type": "cobot"}, {"id": "o", "type": "operator"}],
    "processes": [
        {
            "id": "N",
            "workpiece": "w",
            "actors": ["c", "o"],
            "places": [{"id": "p1", "tokens": 1}, {"id": "p2"}, {"id": "p3"}],
            "transitions": [
                {"id": "to1", "performer": "o", "label": "prepare workpiece"},
                {"id": "tc1", "performer": "c", "label": "place insert"},
            ],
            "arcs": [["p1", "to1"], ["to1", "p2"], ["p2", "tc1"], ["tc1", "p3"]],
        }
    ],
    "constraints": [{"from": "to1", "to": "tc1", "type": "time"}],
}


def valid_document() -> dict[str, Any]:
    """A synchronized pattern that is valid and sound: the operator prepares, the cobot places."""
    return copy.deepcopy(_HAND_OVER)


def document_with_duplicate_ids() -> dict[str, Any]:
    """Right in shape, but the place id p2 is used twice: a draft may hold it, publishing may not."""
    document = valid_document()
    document["processes"][0]["places"].append({"id": "p2"})
    return document


def unsound_document() -> dict[str, Any]:
    """Every rule holds, but the time constraint asks for the cobot's task before the operator's,
    while the net runs them the other way round: the model deadlocks."""
    document = valid_document()
    document["constraints"] = [{"from": "tc1", "to": "to1", "type": "time"}]
    return document
