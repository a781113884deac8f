"""Completed cases with known work times, for the measured times of a prediction."""

import datetime as dt
from typing import Any

from django.contrib.auth.models import User

from hrc.cases import services as case_services
from hrc.cases.models import Case, WorkItem
from hrc.patterns.models import PatternVersion
from tests import factories

START = dt.datetime(2025, 3, 3, 8, 0, tzinfo=dt.UTC)


def sequence_document(first: str = "prep", label: str = "prepare") -> dict[str, Any]:
    """Operators only: `first` (labelled `label`), then pack."""
    return {
        "format": "hrc-pattern/1",
        "name": "Prepare and pack",
        "actors": [{"id": "o", "type": "operator"}],
        "processes": [
            {
                "id": "N",
                "workpiece": "w",
                "actors": ["o"],
                "places": [{"id": "p1", "tokens": 1}, {"id": "p2"}, {"id": "p3"}],
                "transitions": [
                    {"id": first, "performer": "o", "label": label},
                    {"id": "pack", "performer": "o", "label": "pack"},
                ],
                "arcs": [["p1", first], [first, "p2"], ["p2", "pack"], ["pack", "p3"]],
            }
        ],
        "constraints": [],
    }


def completed_case(
    version: PatternVersion,
    *,
    engineer: User,
    operator: User,
    seconds: dict[str, float],
    data: dict[str, Any] | None = None,
) -> Case:
    """A case of `version` whose operator did each task in turn, the task taking its
    `seconds` (the work items' times set afterwards: the services stamp the wall clock)."""
    case = factories.make_case(
        version, started_by=engineer, actor_mapping={"o": {"users": [operator.pk]}}, data=data
    )
    for task, taken in seconds.items():
        item = factories.open_work_item(case, task)
        case_services.start_work_item(item, user=operator)
        case_services.complete_work_item(item, user=operator)
        WorkItem.objects.filter(pk=item.pk).update(
            started_at=START, ended_at=START + dt.timedelta(seconds=taken)
        )
    case.refresh_from_db()
    assert case.status == "completed"
    return case
