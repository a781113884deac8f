"""Test data in one place: people, organisations, cobots, patterns, pattern documents, cases.

Plain functions (no factory library): each makes a valid object with unique
names unless told otherwise, through the services where a service exists.
"""

import copy
import itertools
from typing import Any

from django.contrib.auth.models import User
from django.db import transaction
from django.utils import timezone

from hrc.cases import events as case_events
from hrc.cases import services as case_services
from hrc.cases.choices import OPEN_WORK_ITEM_STATES, IncidentKind, JobState
from hrc.cases.models import Case, Incident, Job, WorkItem
from hrc.cobots import services as cobot_services
from hrc.cobots.choices import DriverKind
from hrc.cobots.models import Cobot
from hrc.organisations import services as organisation_services
from hrc.organisations.choices import Role
from hrc.organisations.models import Organisation
from hrc.patterns import services as pattern_services
from hrc.patterns.models import PatternModel, PatternVersion

_serial = itertools.count(1)

PASSWORD = "a-test-password"


def make_user(username: str | None = None) -> User:
    return organisation_services.provision_user(
        username or f"user{next(_serial)}", password=PASSWORD
    )


def api_key(user: User) -> str:
    """A fresh API key for `user`, as POST /api/token/ would give."""
    key, _ = organisation_services.issue_api_token(user)
    return key


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
    "actors": [
        {"id": "c", "type": "cobot", "program": "Coexistence_PickAndPlace"},
        {"id": "o", "type": "operator"},
    ],
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


# Running cases ---------------------------------------------------------------------------

COUNT_FORM: dict[str, Any] = {
    "type": "object",
    "required": ["count"],
    "properties": {"count": {"type": "integer", "minimum": 1}},
}


def _operator_net(
    transitions: list[dict[str, Any]], arcs: list[list[str]], places: int
) -> dict[str, Any]:
    return {
        "format": "hrc-pattern/1",
        "name": "Operators only",
        "actors": [{"id": "o", "type": "operator"}],
        "processes": [
            {
                "id": "N",
                "workpiece": "w",
                "actors": ["o"],
                "places": [{"id": "p1", "tokens": 1}]
                + [{"id": f"p{n}"} for n in range(2, places + 1)],
                "transitions": transitions,
                "arcs": arcs,
            }
        ],
        "constraints": [],
    }


def _chain(*nodes: str) -> list[list[str]]:
    """Arcs along a path: _chain("p1", "t", "p2") is [["p1", "t"], ["t", "p2"]]."""
    return [[a, b] for a, b in itertools.pairwise(nodes)]


def choice_document() -> dict[str, Any]:
    """Operators only, so no cobot is needed: count the parts (a form), then fix them by hand
    or send them to rework: a deferred choice, whoever starts first decides."""
    return _operator_net(
        [
            {
                "id": "count",
                "performer": "o",
                "label": "count parts",
                "task": {"instructions": "Count the parts on the tray.", "form": COUNT_FORM},
            },
            {"id": "fix", "performer": "o", "label": "fix by hand"},
            {"id": "rework", "performer": "o", "label": "send to rework"},
        ],
        _chain("p1", "count", "p2", "fix", "p3") + _chain("p2", "rework", "p3"),
        places=3,
    )


def message_document() -> dict[str, Any]:
    """Operators only: prepare the order, wait for the message `part-ready` about this case's
    order (correlation key `order` = data.order), then assemble."""
    return _operator_net(
        [
            {"id": "prepare", "performer": "o", "label": "prepare order"},
            {
                "id": "arrive",
                "message": {"name": "part-ready", "correlation": {"order": "data.order"}},
            },
            {"id": "assemble", "performer": "o", "label": "assemble"},
        ],
        _chain("p1", "prepare", "p2", "arrive", "p3", "assemble", "p4"),
        places=4,
    )


def make_version(
    organisation: Organisation, *, published_by: User, draft: object = None
) -> PatternVersion:
    """A published version (of valid_document() unless told otherwise)."""
    pattern = make_pattern(organisation, draft=draft, created_by=published_by)
    return pattern_services.publish_pattern(pattern, published_by=published_by)


def make_case(
    version: PatternVersion,
    *,
    started_by: User,
    actor_mapping: dict[str, Any],
    data: dict[str, Any] | None = None,
) -> Case:
    return case_services.start_case(
        version, started_by=started_by, actor_mapping=actor_mapping, data=data
    )


def hand_over_case(
    version: PatternVersion, *, started_by: User, operator: User, cobot: Cobot
) -> Case:
    """A case of the hand-over pattern (valid_document()) whose operator has prepared the
    workpiece (to1 done): its cobot step is leased for the workers when the cobot was free
    (the completion hands it over; no worker has claimed it), else it waits in the queue."""
    item = hand_over_started(version, started_by=started_by, operator=operator, cobot=cobot)
    case_services.complete_work_item(item, user=operator)
    return item.case


def hand_over_started(
    version: PatternVersion, *, started_by: User, operator: User, cobot: Cobot
) -> WorkItem:
    """The operator task (to1) of a new case of the hand-over pattern, started by `operator`:
    its completion enables the cobot's step."""
    case = make_case(
        version, started_by=started_by,
        actor_mapping={"o": {"users": [operator.pk]}, "c": {"cobot": cobot.pk}},
    )  # fmt: skip
    item = open_work_item(case, "to1")
    case_services.start_work_item(item, user=operator)
    return item


def open_work_item(case: Case, task: str) -> WorkItem:
    """The case's open work item for the task; fails when there is none."""
    return WorkItem.objects.get(case=case, task=task, state__in=sorted(OPEN_WORK_ITEM_STATES))


def make_incident(item: WorkItem, message: str = "The step failed.") -> Incident:
    """An open incident about a work item, as a worker opens one (holding the case row lock):
    the item's job, if it has one, failed."""
    with transaction.atomic():
        case = Case.objects.select_for_update().get(pk=item.case_id)
        Job.objects.filter(work_item=item).update(state=JobState.FAILED, ended_at=timezone.now())
        incident = case_events.open_incident(
            case, IncidentKind.STEP_FAILED, message, item=item, cobot_state={"RobotMode": 7}
        )
        case.save()
    return incident
