"""Run as `python -m tests.cases.sqlite_writers CASES` on the embedded SQLite (DATABASE_URL unset):
two operators, each on a thread with its own connection, complete their parallel tasks of the
same cases at the same moment. Prints one JSON object: what each case's log and open tasks
say, and the errors the threads met. test_sqlite_writers.py checks it."""

from __future__ import annotations

import json
import socket
import sys
import threading
import time
from typing import Any

import django

django.setup()

from django.db import connection, connections, transaction  # noqa: E402

from hrc.cases import interruptions, services  # noqa: E402
from hrc.cases.choices import InterruptionMode  # noqa: E402
from hrc.cases.models import Case, CaseEvent, Interruption, Job, Message  # noqa: E402
from hrc.cobots.models import Cobot  # noqa: E402
from hrc.database import ensure_migrated  # noqa: E402
from hrc.organisations.choices import Role  # noqa: E402
from tests import factories  # noqa: E402

# The operator o1 prepares, then o1 and o2 each do their half at once, then o1 joins them.
SPLIT_AND_JOIN: dict[str, Any] = {
    "format": "hrc-pattern/1",
    "name": "Two halves at once",
    "actors": [{"id": "o1", "type": "operator"}, {"id": "o2", "type": "operator"}],
    "processes": [
        {
            "id": "N",
            "workpiece": "w",
            "actors": ["o1", "o2"],
            "places": [{"id": "p1", "tokens": 1}] + [{"id": f"p{n}"} for n in range(2, 7)],
            "transitions": [
                {"id": "prepare", "performer": "o1", "label": "prepare"},
                {"id": "left", "performer": "o1", "label": "left half"},
                {"id": "right", "performer": "o2", "label": "right half"},
                {"id": "join", "performer": "o1", "label": "join halves"},
            ],
            "arcs": [
                ["p1", "prepare"], ["prepare", "p2"], ["prepare", "p3"],
                ["p2", "left"], ["left", "p4"], ["p3", "right"], ["right", "p5"],
                ["p4", "join"], ["p5", "join"], ["join", "p6"],
            ],
        }
    ],
    "constraints": [],
}  # fmt: skip


def main(count: int) -> dict[str, Any]:
    assert connection.vendor == "sqlite", connection.vendor
    ensure_migrated(migrate_sqlite=True)
    organisation = factories.make_organisation()
    first = factories.make_member(organisation, Role.OPERATOR)
    second = factories.make_member(organisation, Role.OPERATOR)
    engineer = factories.make_member(organisation, Role.ENGINEER)
    version = factories.make_version(organisation, published_by=engineer, draft=SPLIT_AND_JOIN)
    mapping = {"o1": {"users": [first.pk]}, "o2": {"users": [second.pk]}}
    cases = []
    for _ in range(count):
        case = factories.make_case(version, started_by=engineer, actor_mapping=mapping)
        prepare = factories.open_work_item(case, "prepare")
        services.start_work_item(prepare, user=first)
        services.complete_work_item(prepare, user=first)
        cases.append(case)
    items = {
        task: [factories.open_work_item(case, task).pk for case in cases]
        for task in ("left", "right")
    }
    errors: list[str] = []
    together = threading.Barrier(2)

    def operator(task: str, user: Any) -> None:
        try:
            for pk in items[task]:
                services.start_work_item(pk, user=user)
                together.wait(timeout=30)  # both halves of a case complete at the same moment
                services.complete_work_item(pk, user=user)
        except Exception as error:
            errors.append(f"{task}: {type(error).__name__}: {error}")
            together.abort()
        finally:
            connections.close_all()

    threads = [
        threading.Thread(target=operator, args=("left", first)),
        threading.Thread(target=operator, args=("right", second)),
    ]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    return {
        "errors": errors,
        "row_locks": row_locks(),
        "pause": pause_a_silent_cobot(cases[0], first),
        "cases": [
            {
                "completed": sorted(
                    CaseEvent.objects.filter(case=case, type="task-completed").values_list(
                        "task", flat=True
                    )
                ),
                "open": sorted(
                    Case.objects.get(pk=case.pk)
                    .work_items.exclude(state__in=["completed", "withdrawn"])
                    .values_list("task", flat=True)
                ),
            }
            for case in cases
        ],
    }


def pause_a_silent_cobot(case: Case, operator: Any) -> dict[str, Any]:
    """Pauses a cobot whose gateway accepts the connection and never answers, while an
    operator's write waits: how long each took, and what the interruption recorded."""
    silent = socket.socket()
    silent.bind(("127.0.0.1", 0))
    silent.listen()
    cobot = factories.make_cobot(
        case.organisation, endpoint=f"opc.tcp://127.0.0.1:{silent.getsockname()[1]}"
    )
    item = factories.open_work_item(case, "join")
    interruption = Interruption.objects.create(
        case=case, work_item=item, by_work_item=item, cobot=cobot,
        mode=InterruptionMode.PAUSE,
    )  # fmt: skip
    started = time.monotonic()

    def pause() -> None:
        try:
            interruptions.interrupt_cobot(interruption.pk)
        finally:
            connections.close_all()

    pausing = threading.Thread(target=pause)
    pausing.start()
    time.sleep(0.5)  # the pause is waiting for the gateway by now
    writing = time.monotonic()
    services.claim_work_item(item.pk, user=operator)
    wrote = time.monotonic() - writing
    pausing.join()
    silent.close()
    interruption.refresh_from_db()
    return {
        "pause_seconds": time.monotonic() - started,
        "write_seconds": wrote,
        "paused_at": str(interruption.paused_at),
        "error": interruption.error,
    }


def row_locks() -> int:
    """The runtime's select_for_update forms, evaluated on SQLite (where Django drops them)."""
    with transaction.atomic():
        found = [
            *Cobot.objects.select_for_update(of=("self",), no_key=True),
            *Job.objects.select_for_update(of=("self",), no_key=True).select_related("cobot"),
            *Message.objects.select_for_update(skip_locked=True),
            *Case.objects.select_for_update(nowait=True),
        ]
    return len(found)


if __name__ == "__main__":
    print(json.dumps(main(int(sys.argv[1]))))
