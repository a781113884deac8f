"""The times a pattern's completed cases measured, for a prediction: by task id and by label,
the branches taken, and nothing of another organisation's cases."""

from typing import Any

import pytest
from django.contrib.auth.models import User

from hrc.analytics import selectors
from hrc.analytics.selectors import measured_times
from hrc.organisations.choices import Role
from hrc.organisations.models import Organisation
from hrc.patterns.prediction import measured_for
from tests import factories
from tests.patterns.measured_cases import completed_case, sequence_document


def _version(organisation: Organisation, engineer: User, draft: dict[str, Any]) -> Any:
    return factories.make_version(organisation, published_by=engineer, draft=draft)


def test_the_work_times_of_completed_tasks_by_id_and_by_label(
    organisation: Organisation, engineer: User, operator: User
) -> None:
    version = _version(organisation, engineer, sequence_document())
    for prep in (3, 5):
        completed_case(
            version, engineer=engineer, operator=operator, seconds={"prep": prep, "pack": 7}
        )
    factories.make_case(  # running: not counted
        version, started_by=engineer, actor_mapping={"o": {"users": [operator.pk]}}
    )

    measured = measured_times(version.pattern)

    assert sorted(measured.by_task["prep"]) == [3, 5]
    assert measured.by_task["pack"] == [7, 7]
    assert sorted(measured.by_label["prepare"]) == [3, 5]
    assert measured_for(version.pattern) == measured  # the reader analytics registers


def test_the_branches_each_choice_took_are_counted(
    organisation: Organisation, engineer: User, operator: User
) -> None:
    draft = sequence_document()
    draft["data"] = {"rush": False}
    net = draft["processes"][0]
    net["places"].append({"id": "p4"})
    net["transitions"] += [
        {"id": "rush", "guard": "data.rush"},
        {"id": "calm", "guard": "not data.rush"},
    ]
    net["arcs"] = [a for a in net["arcs"] if a[0] != "p1"] + [
        ["p1", "rush"], ["p1", "calm"], ["rush", "p4"], ["calm", "p4"], ["p4", "prep"]
    ]  # fmt: skip
    version = _version(organisation, engineer, draft)
    for rush in (True, False, False):
        case = completed_case(
            version, engineer=engineer, operator=operator, seconds={"prep": 1, "pack": 1},
            data={"rush": rush},
        )  # fmt: skip
        assert case.status == "completed"

    measured = measured_times(version.pattern)
    assert measured.transitions == frozenset({"rush", "calm"})
    assert measured.fired == {"rush": 1, "calm": 2}


def test_another_organisations_cases_are_not_counted(
    organisation: Organisation,
    other_organisation: Organisation,
    engineer: User,
    operator: User,
    outsider: User,
) -> None:
    ours = _version(organisation, engineer, sequence_document())
    theirs = _version(other_organisation, outsider, sequence_document())
    their_operator = factories.make_member(other_organisation, Role.OPERATOR, "tom-their-operator")
    completed_case(
        theirs, engineer=outsider, operator=their_operator, seconds={"prep": 99, "pack": 99}
    )
    completed_case(ours, engineer=engineer, operator=operator, seconds={"prep": 2, "pack": 2})

    measured = measured_times(ours.pattern)

    assert measured.by_task == {"prep": [2], "pack": [2]}
    assert measured.by_label == {"prepare": [2], "pack": [2]}


def test_only_the_latest_cases_are_measured(
    organisation: Organisation, engineer: User, operator: User, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(selectors, "MEASURED_CASES", 2)
    version = _version(organisation, engineer, sequence_document())
    for prep in (30, 4, 6):  # the oldest first
        completed_case(
            version, engineer=engineer, operator=operator, seconds={"prep": prep, "pack": 7}
        )

    assert sorted(measured_times(version.pattern).by_task["prep"]) == [4, 6]
