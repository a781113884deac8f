"""The event stream tested the way Zulip tests its own: the deltas a tablet received while cases
ran, applied to the snapshot it started from (by the tablet's own TypeScript store), give
exactly the snapshot a tablet that connects afterwards gets."""

from __future__ import annotations

import datetime as dt
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from django.db.models import Max

from hrc.cases import services as case_services
from hrc.cases.choices import CaseStatus, JobState, WorkItemState
from hrc.cases.models import Case, Job, WorkItem
from hrc.cases.simulation import Simulation
from hrc.live import groups
from tests.cases.patterns import cobot_chain
from tests.live.client import db, open_socket, receive, receive_until, run
from tests.live.replay import replay
from tests.live.server import LiveServer, session_cookie
from tests.support.polling import until

pytestmark = pytest.mark.django_db(transaction=True)


@pytest.fixture
def simulation(tmp_path: Path) -> Iterator[Simulation]:
    with Simulation(cobot_chain(steps=2), tmp_path, time_scale=0.02) as running:
        yield running


def _comparable(snapshot: dict[str, Any]) -> dict[str, Any]:
    """Without what is not a case's: when the server read a cobot queue, the gateway's state."""
    copy = {key: value for key, value in snapshot.items() if key != "type"}
    copy["cobots"] = [
        {**cobot, "state": None, "queue": {**cobot["queue"], "at": 0}} for cobot in copy["cobots"]
    ]
    return copy


def _operator_item(case_id: int) -> WorkItem:
    return WorkItem.objects.get(case_id=case_id, task="to1", state=WorkItemState.OFFERED)


def test_deltas_applied_to_an_old_snapshot_give_the_fresh_snapshot(
    server: LiveServer, simulation: Simulation
) -> None:
    operator = simulation.users["o"]
    cookie = session_cookie(operator)
    captured: list[dict[str, Any]] = []

    def run_cases(first: int, second: int, third: int) -> float:
        """Two cases run to their end while a third waits, started, and a fourth is offered.

        Returns when the last step finished (seconds since the epoch)."""
        for case_id in (first, second):
            item = _operator_item(case_id)
            case_services.start_work_item(item, user=operator)
            case_services.complete_work_item(item, user=operator)
        case_services.start_work_item(_operator_item(third), user=operator)
        simulation.start_cases(1)
        until(
            lambda: (
                Case.objects.filter(pk__in=[first, second], status=CaseStatus.COMPLETED).count()
                == 2
            ),
            timeout=60,
        )
        until(
            lambda: not Job.objects.filter(state__in=[JobState.QUEUED, JobState.RUNNING]).exists(),
            timeout=60,
        )
        groups.flush()
        last_finish: dt.datetime = Job.objects.aggregate(last=Max("ended_at"))["last"]
        return last_finish.timestamp()

    async def scenario() -> None:
        cases = await db(simulation.start_cases, 3)
        await db(groups.flush)
        socket = await open_socket(server, cookie)
        old = await receive(socket)
        assert [case["id"] for case in old["cases"]] == cases
        with simulation.running(operators=False):
            last_finish = await db(run_cases, *cases)
        # The last case deltas are the two cases' completions and the new case's offer (in
        # either order). The cobot's queue is read apart from them, by whichever process
        # changed it, a window later: its last word is an empty queue read after the last
        # step finished, and the newest read wins. (A resync at once could be answered first:
        # the socket's frames and the channel layer's messages race in the consumer.)
        last: set[tuple[str, int]] = set()
        newest_queue: dict[str, Any] = {"at": 0.0}

        def all_sent_arrived(event: dict[str, Any]) -> bool:
            kind = event.get("event")  # cobot queues have none
            if kind == "case-completed" or (kind == "task-offered" and event["case"] not in cases):
                last.add((kind, event["case"]))
            if event["type"] == "cobot-queue" and event["queue"]["at"] > newest_queue["at"]:
                newest_queue.update(event["queue"])
            queue_settled = newest_queue["at"] > last_finish and newest_queue["current"] is None
            return len(last) == 3 and queue_settled

        await receive_until(socket, all_sent_arrived, into=captured)
        await socket.send('{"type": "resync"}')
        fresh = await receive_until(socket, lambda e: e["type"] == "snapshot", into=captured)
        captured.pop()
        await socket.close()

        kinds = {event["type"] for event in captured}
        assert {"case", "work-item", "cobot-queue"} <= kinds
        assert len(fresh["cases"]) == 2  # the waiting case and the new one
        assert {item["state"] for item in fresh["work_items"]} == {"running", "offered"}

        replayed = replay([old, *captured])
        assert replayed["holes"] is False
        assert _comparable({"type": "", **replayed["state"]}) == _comparable(fresh)

    run(scenario())


def test_a_missed_delta_is_found_by_its_number(server: LiveServer, simulation: Simulation) -> None:
    """Deltas left out of a capture (a channel-layer message lost) leave the store with a hole."""
    operator = simulation.users["o"]
    cookie = session_cookie(operator)

    async def scenario() -> None:
        [case_id] = await db(simulation.start_cases, 1)
        await db(groups.flush)
        socket = await open_socket(server, cookie)
        old = await receive(socket)
        item = await db(_operator_item, case_id)
        await db(case_services.claim_work_item, item, user=operator)
        await db(case_services.unclaim_work_item, item, user=operator)
        await db(case_services.claim_work_item, item, user=operator)
        await db(groups.flush)
        deltas = [await receive(socket) for _ in range(3)]
        assert [d["seq"] for d in deltas] == [old["cases"][0]["seq"] + n for n in (1, 2, 3)]

        assert replay([old, *deltas])["holes"] is False
        lost_one = replay([old, deltas[0], deltas[2]])
        assert lost_one["holes"] is True
        assert lost_one["outcomes"] == ["applied", "applied", "held"]

    run(scenario())
