"""Space constraints for every pair of actors, at run time, on simulated gateways: the second
operator refused while the first works in the area; two cobots' steps never at once ("wait"),
or the running one paused ("pause"); a cobot beside an operator slowed, not held ("slow").

The simulators' step logs (hrc_gateway.sim.state.read_step_log) say when each step ran and at
what speed override."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any

import pytest

from hrc.cases import dispatch, services
from hrc.cases.choices import CaseStatus, EventType, InterruptionMode, JobState, WorkItemState
from hrc.cases.interruptions import SLOW_OVERRIDE_PERCENT
from hrc.cases.models import Case, Interruption, Job, WorkItem
from hrc.cases.simulation import Simulation
from hrc.errors import Conflict
from hrc_gateway import urua
from tests.cases.patterns import PICK, PROGRAM
from tests.support.polling import until
from tests.support.workers import WorkerProcess

pytestmark = pytest.mark.django_db(transaction=True)


def _document(
    actors: dict[str, str],
    lanes: list[list[tuple[str, str]]],
    space: tuple[str, str],
    mode: str | None = None,
    after: list[tuple[str, str]] = (),  # type: ignore[assignment]
) -> dict[str, Any]:
    """Lanes of (task, actor) side by side after an AND-split, joined, then the `after` tasks;
    one space constraint between the tasks `space`."""
    transitions: list[dict[str, Any]] = [{"id": "split"}, {"id": "join"}]
    arcs, places = [["p0", "split"]], ["p0", "pj"]
    for number, lane in enumerate(lanes):
        previous = f"l{number}_0"
        arcs.append(["split", previous])
        places.append(previous)
        for index, (task, actor) in enumerate(lane, start=1):
            transitions.append(_task(task, actor, actors[actor]))
            place = f"l{number}_{index}"
            arcs += [[previous, task], [task, place]]
            places.append(place)
            previous = place
        arcs.append([previous, "join"])
    arcs.append(["join", "pj"])
    previous = "pj"
    for index, (task, actor) in enumerate(after):
        transitions.append(_task(task, actor, actors[actor]))
        arcs += [[previous, task], [task, f"pa{index}"]]
        places.append(f"pa{index}")
        previous = f"pa{index}"
    constraint: dict[str, Any] = {"from": space[0], "to": space[1], "type": "space"}
    if mode is not None:
        constraint["interrupt"] = mode
    return {
        "format": "hrc-pattern/1",
        "name": "Shared area",
        "actors": [
            {"id": a, "type": t, **({"program": PROGRAM} if t == "cobot" else {})}
            for a, t in actors.items()
        ],
        "processes": [
            {
                "id": "N",
                "workpiece": "w",
                "actors": list(actors),
                "places": [{"id": p, "tokens": 1 if p == "p0" else 0} for p in places],
                "transitions": transitions,
                "arcs": arcs,
            }
        ],
        "constraints": [constraint],
    }


def _task(task: str, actor: str, kind: str) -> dict[str, Any]:
    if kind == "operator":
        return {"id": task, "performer": actor, "label": f"{task} by {actor}"}
    return {
        "id": task, "performer": actor, "label": f"{task} by {actor}",
        "task": {"step": {"number": PICK}, "timeout": 30},
    }  # fmt: skip


def _offered(case: Case, task: str) -> WorkItem:
    item: WorkItem = until(
        lambda: WorkItem.objects.filter(case=case, task=task, state=WorkItemState.OFFERED).first()
    )
    return item


@pytest.fixture
def doorbells_only() -> Iterator[None]:
    """Jobs run on this process's threads when their doorbell rings; no sweeper rings them."""
    with ThreadPoolExecutor(max_workers=4) as pool, dispatch.run_inline(pool):
        yield


# Operator and operator --------------------------------------------------------------------


def test_the_second_operator_is_refused_while_the_first_works_in_the_area_and_allowed_after(
    tmp_path: Path,
) -> None:
    document = _document(
        {"o1": "operator", "o2": "operator"}, [[("to1", "o1")], [("to2", "o2")]], ("to1", "to2")
    )
    with Simulation(document, tmp_path) as simulation:
        [case_id] = simulation.start_cases(1)
        case = Case.objects.get(pk=case_id)
        first, second = simulation.users["o1"], simulation.users["o2"]
        inspecting = services.start_work_item(_offered(case, "to1"), user=first)

        for _ in range(2):  # pressed twice: one interruption
            with pytest.raises(Conflict) as refused:
                services.start_work_item(_offered(case, "to2"), user=second)
            assert "to1 by o1" in str(refused.value)
            assert first.username in str(refused.value)
        [interruption] = Interruption.objects.filter(case=case)
        assert (interruption.work_item.task, interruption.by_work_item.task) == ("to2", "to1")
        assert (interruption.mode, interruption.cobot, interruption.ended_at) == (
            InterruptionMode.REFUSED, None, None,
        )  # fmt: skip
        [kept_out] = case.events.filter(type=EventType.TASK_KEPT_OUT)
        assert kept_out.task == "to2"
        assert kept_out.detail["by"] == "to1"
        assert kept_out.detail["by_performer"] == first.username

        services.complete_work_item(inspecting, user=first)
        services.start_work_item(_offered(case, "to2"), user=second)

    interruption.refresh_from_db()
    assert interruption.ended_at is not None
    assert interruption.seconds is not None
    assert WorkItem.objects.get(case=case, task="to2").state == WorkItemState.RUNNING


# Cobot and cobot --------------------------------------------------------------------------

TWO_COBOTS = {"c1": "cobot", "c2": "cobot"}
# c1 picks in the area at once; c2 picks elsewhere first, then in the area (tc2).
TWO_COBOT_LANES = [[("tc1", "c1")], [("tc0", "c2"), ("tc2", "c2")]]


def _overlap(one: dict[str, Any], other: dict[str, Any]) -> bool:
    return bool(one["started"] < other["ended"] and other["started"] < one["ended"])


def test_two_cobots_sharing_an_area_never_run_their_steps_at_once(
    tmp_path: Path, start_worker: Callable[..., WorkerProcess]
) -> None:
    document = _document(TWO_COBOTS, [[("tc1", "c1")], [("tc2", "c2")]], ("tc1", "tc2"))
    # No beat: no sweeper rings a waiting job; only the doorbell of the area freed does.
    with Simulation(document, tmp_path, time_scale=0.5, inline=False) as simulation:
        start_worker()
        start_worker()
        cases = simulation.start_cases(2)
        waiting = until(
            lambda: Job.objects.filter(case_id__in=cases).exclude(waiting_for="").first()
        )
        assert simulation.wait(cases, timeout=90)
        steps = simulation.step_log("c1") + simulation.step_log("c2")

    assert Case.objects.filter(pk__in=cases, status=CaseStatus.COMPLETED).count() == 2
    assert len(steps) == 4
    by_case: dict[int, list[dict[str, Any]]] = {}
    for job in Job.objects.filter(case_id__in=cases):
        token = [job.pk, job.attempt]
        by_case.setdefault(job.case_id, []).extend(s for s in steps if s["token"] == token)
    for case_steps in by_case.values():
        one, other = case_steps
        assert not _overlap(one, other), case_steps
    # The step kept out waited, naming the task in the area and its cobot.
    assert "is in the shared area" in waiting.waiting_for
    held = Interruption.objects.filter(case_id__in=cases, mode=InterruptionMode.WAIT)
    assert held.count() >= 1
    # One interruption per waiting step, however often its doorbell rang meanwhile.
    assert len({i.work_item_id for i in held}) == held.count()
    for interruption in held:
        assert interruption.ended_at is not None
        occupant = interruption.by_work_item
        assert {interruption.work_item.task, occupant.task} == {"tc1", "tc2"}


def test_in_pause_mode_the_later_step_runs_and_the_running_cobot_is_paused(
    tmp_path: Path, doorbells_only: None
) -> None:
    document = _document(TWO_COBOTS, TWO_COBOT_LANES, ("tc1", "tc2"), mode="pause")
    with Simulation(document, tmp_path, time_scale=0.5, inline=False) as simulation:
        first = simulation.cobot("c1")
        first.call("Simulator/InjectFault", "slow-steps", "6")  # tc1 runs ~6 s: tc2 comes in
        [case_id] = simulation.start_cases(1)
        until(lambda: first.read(urua.STATE_PROGRAM_STATE) == urua.PROGRAM_PAUSED, timeout=30)
        first.call("Simulator/ClearFault")
        assert simulation.wait([case_id], timeout=90)
        [tc1] = simulation.step_log("c1")
        tc2 = simulation.step_log("c2")[-1]

    assert Case.objects.get(pk=case_id).status == CaseStatus.COMPLETED
    [interruption] = Interruption.objects.filter(case_id=case_id)
    assert (interruption.work_item.task, interruption.by_work_item.task) == ("tc1", "tc2")
    assert interruption.mode == InterruptionMode.PAUSE
    assert None not in (interruption.paused_at, interruption.resumed_at, interruption.ended_at)
    # tc1 ran before tc2 and was still running when tc2 ended: it was held meanwhile.
    assert tc1["started"] < tc2["started"] < tc2["ended"] < tc1["ended"]


# Operator and cobot, slow -------------------------------------------------------------------


def test_slow_lets_the_cobot_start_at_the_reduced_speed_and_restores_it_after(
    tmp_path: Path, doorbells_only: None
) -> None:
    # The operator inspects (to2) from the start; the cobot picks (tc1) once to1 is done,
    # beside the operator; after both, a pick (tc2) with nobody in the area.
    document = _document(
        {"c": "cobot", "o": "operator"},
        [[("to1", "o"), ("tc1", "c")], [("to2", "o")]],
        ("to2", "tc1"),
        mode="slow",
        after=[("tc2", "c")],
    )
    with Simulation(document, tmp_path, time_scale=0.2, inline=False) as simulation:
        [case_id] = simulation.start_cases(1)
        case = Case.objects.get(pk=case_id)
        operator = simulation.users["o"]
        inspecting = services.start_work_item(_offered(case, "to2"), user=operator)
        loading = services.start_work_item(_offered(case, "to1"), user=operator)
        services.complete_work_item(loading, user=operator)
        until(lambda: Job.objects.filter(case=case, work_item__task="tc1", state=JobState.SUCCEEDED).exists())  # fmt: skip
        services.complete_work_item(inspecting, user=operator)
        assert simulation.wait([case_id], timeout=60)
        slowed, full = simulation.step_log("c")

    assert Case.objects.get(pk=case_id).status == CaseStatus.COMPLETED
    assert slowed["override"] == SLOW_OVERRIDE_PERCENT
    assert full["override"] == full["lowest_override"] == 100.0
    [interruption] = Interruption.objects.filter(case=case)
    assert (interruption.work_item.task, interruption.by_work_item.task) == ("tc1", "to2")
    assert interruption.mode == InterruptionMode.SLOW
    assert None not in (interruption.paused_at, interruption.resumed_at, interruption.ended_at)
