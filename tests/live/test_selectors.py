"""What the tablets read: a cobot's queue, as its panel shows it; where the floor's cobots stand."""

from __future__ import annotations

import pytest
from django.contrib.auth.models import User
from django.db import connection
from django.test.utils import CaptureQueriesContext

from hrc.cases import jobs
from hrc.cases.models import Job
from hrc.cobots.models import Cobot
from hrc.live.selectors import access_of, cobot_queues, snapshot
from hrc.organisations.models import Organisation
from tests import factories
from tests.cases.patterns import func_hold

pytestmark = pytest.mark.django_db


def test_a_cobots_queue_counts_its_jobs_names_the_running_step_and_the_first_reason_to_wait(
    organisation: Organisation, engineer: User, operator: User, cobot: Cobot
) -> None:
    version = factories.make_version(organisation, published_by=engineer)
    idle = factories.make_cobot(organisation, cell="paint")
    cases = [
        factories.hand_over_case(version, started_by=operator, operator=operator, cobot=cobot)
        for _ in range(4)
    ]
    lease = jobs.lease_next_job(cobot.pk)  # the first case's step runs
    assert lease is not None
    assert lease.case_id == cases[0].pk
    # The third case's step waits (say, for an operator in a shared area), then the fourth's.
    queued = Job.objects.filter(case__in=cases[2:]).order_by("queued_at", "id")
    Job.objects.filter(pk=queued[1].pk).update(waiting_for="the fourth's reason")
    Job.objects.filter(pk=queued[0].pk).update(waiting_for="the third's reason")

    rows = cobot_queues([idle.pk, cobot.pk])

    assert [(org, cell) for org, cell, _ in rows] == [
        (organisation.pk, "paint"),
        (organisation.pk, cobot.cell),
    ]  # in the order asked
    assert {key: rows[0][2][key] for key in ("cobot", "queue_length", "current", "waiting_for")} == {
        "cobot": idle.pk, "queue_length": 0, "current": None, "waiting_for": "",
    }  # fmt: skip
    queue = rows[1][2]
    assert (queue["cobot"], queue["queue_length"], queue["waiting_for"]) == (
        cobot.pk, 4, "the third's reason",
    )  # fmt: skip
    running = Job.objects.get(pk=lease.job_id)
    assert isinstance(running.command["number"], int)  # the program step the cobot runs
    assert queue["current"] == {
        "case": cases[0].pk, "work_item": running.work_item_id,
        "task": "tc1", "label": "place insert", "kind": "step",
        "step": running.command["number"], "attempt": 1,
    }  # fmt: skip


def test_a_long_queue_is_read_as_one_row_per_cobot_with_a_reason_far_down_the_queue(
    organisation: Organisation, engineer: User, operator: User, cobot: Cobot
) -> None:
    version = factories.make_version(organisation, published_by=engineer)
    cases = [
        factories.hand_over_case(version, started_by=operator, operator=operator, cobot=cobot)
        for _ in range(30)
    ]
    assert jobs.lease_next_job(cobot.pk) is not None
    *_, last = Job.objects.filter(case__in=cases).order_by("queued_at", "id")
    Job.objects.filter(pk=last.pk).update(waiting_for="the last one's reason")

    with CaptureQueriesContext(connection) as captured:
        [(_, _, queue)] = cobot_queues([cobot.pk])

    assert (queue["queue_length"], queue["waiting_for"]) == (30, "the last one's reason")
    assert queue["current"] is not None
    assert queue["current"]["case"] == cases[0].pk
    [statement] = captured.captured_queries
    with connection.cursor() as cursor:  # the database counts: a row per cobot comes back
        cursor.execute(statement["sql"])
        assert len(cursor.fetchall()) == 1


def test_a_cobots_queue_says_what_another_cases_func_hold_waits_for(
    organisation: Organisation, engineer: User, operator: User, cobot: Cobot
) -> None:
    version = factories.make_version(organisation, published_by=engineer, draft=func_hold())
    mapping = {"c": {"cobot": cobot.pk}, "o": {"users": [operator.pk]}}
    holder, _ = (
        factories.make_case(version, started_by=engineer, actor_mapping=mapping) for _ in range(2)
    )
    lease = jobs.lease_next_job(cobot.pk)
    assert lease is not None
    jobs.finish_job(lease, {"outcome": "ran", "seconds": 0.5})  # held until to1 completes
    assert jobs.lease_next_job(cobot.pk) is None

    [(_, _, queue)] = cobot_queues([cobot.pk])

    assert queue["queue_length"] == 1  # the other case's step; the holding one has run
    assert queue["current"] is None
    assert queue["waiting_for"] == f"holding for: screw the part, case {holder.pk}"


def test_a_cell_tablet_gets_its_cells_cobots_and_where_every_other_cobot_of_ours_stands(
    organisation: Organisation, other_organisation: Organisation, operator: User
) -> None:
    weld = factories.make_cobot(organisation, name="weld-arm", cell="weld")
    paint = factories.make_cobot(organisation, name="paint-arm", cell="paint")
    loose = factories.make_cobot(organisation, name="spare")
    factories.make_cobot(other_organisation, name="their-arm", cell="weld")
    access = access_of(operator, organisation.pk)
    assert access is not None

    weld_tablet = snapshot(access, "weld")

    assert [cobot["id"] for cobot in weld_tablet["cobots"]] == [weld.pk]
    assert weld_tablet["floor"] == [
        {"id": weld.pk, "name": "weld-arm", "cell": "weld"},
        {"id": paint.pk, "name": "paint-arm", "cell": "paint"},
        {"id": loose.pk, "name": "spare", "cell": ""},
    ]  # by id; nothing of the other organisation
    assert snapshot(access, "")["floor"] == weld_tablet["floor"]


def test_a_snapshot_reads_as_often_for_ten_cobots_cases_and_incidents_as_for_one(
    organisation: Organisation, engineer: User, operator: User
) -> None:
    # A tablet's first message: 200 tablets connecting at a shift change read it at once.
    version = factories.make_version(organisation, published_by=engineer)

    def floor(count: int) -> None:  # a cobot with a queued step, an incident, an operator's task
        for _ in range(count):
            cobot = factories.make_cobot(organisation, cell="weld")
            case = factories.hand_over_case(version, started_by=operator, operator=operator,
                                            cobot=cobot)  # fmt: skip
            factories.make_incident(factories.open_work_item(case, "tc1"))
            factories.make_case(version, started_by=operator,
                                actor_mapping={"o": {"users": [operator.pk]}, "c": {"cobot": cobot.pk}})  # fmt: skip

    def statements() -> int:
        access = access_of(operator, organisation.pk)
        assert access is not None
        with CaptureQueriesContext(connection) as captured:
            shown = snapshot(access, "weld")
        assert len(shown["cobots"]) == len(shown["incidents"]) == len(shown["cases"]) // 2
        return len(captured.captured_queries)

    floor(1)
    one = statements()
    floor(9)
    assert statements() == one
