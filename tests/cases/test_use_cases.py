"""The seven use cases of the prototype (hrc/patterns/examples/use_cases/) run for real, with hrc's
variants of them beside (a letter after the number, "variant" in the name).

Each test runs its use case to completion as `run_pattern --simulate` does,
but with real Celery worker processes on a private broker and a simulated
OPC UA gateway per cobot, and checks the outcome in the case data, the
trace (task events) and what the simulators themselves counted. Every trace
must also keep every constraint as pattern-format.md defines it.
"""

from __future__ import annotations

import itertools
import json
from collections import Counter
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pytest

from hrc.cases.choices import CaseStatus, EventType, JobState, WorkItemKind
from hrc.cases.models import Case, Incident, Interruption, Job, Message
from hrc.cases.simulation import Simulation
from hrc.engine import check_document, read_pattern
from tests.cases.test_run_pattern import check_trace
from tests.support.workers import WorkerProcess

USE_CASES = Path(__file__).resolve().parents[2] / "hrc" / "patterns" / "examples" / "use_cases"
# Robot time runs fifty times faster: a 2 s tool wait takes 40 ms.
TIME_SCALE = 0.02
TIMEOUT = 300.0

Event = dict[str, Any]


def load(stem: str) -> dict[str, Any]:
    document: dict[str, Any] = json.loads((USE_CASES / f"{stem}.json").read_text())
    return document


@dataclass
class Run:
    document: dict[str, Any]
    cases: list[Case]
    trace: list[Event]
    executions: dict[str, int]  # steps each simulated cobot ran, by its own count
    devices: dict[str, dict[str, Any]]  # each cobot's Devices/ variables at the end

    def case_trace(self, case: Case) -> list[Event]:
        return [event for event in self.trace if event["case"] == case.pk]

    def completed(self, case: Case) -> Counter[str]:
        return Counter(e["task"] for e in self.case_trace(case) if e["event"] == "task-completed")


def run_use_case(
    stem: str,
    workdir: Path,
    start_worker: Callable[..., WorkerProcess],
    *,
    cases: int = 1,
    workers: int = 1,
    before: Callable[[Simulation], None] | None = None,
) -> Run:
    """Runs `cases` cases of the use case on `workers` real Celery workers until they end."""
    document = load(stem)
    for index in range(workers):
        start_worker(beat=index == 0)
    with Simulation(document, workdir, time_scale=TIME_SCALE, inline=False, seed=7) as simulation:
        if before is not None:
            before(simulation)
        with simulation.running():
            ids = simulation.start_cases(cases)
            assert simulation.wait(ids, timeout=TIMEOUT), f"{stem}: the cases did not end in time"
        trace = [event.as_dict() for event in simulation.events(ids)]
        executions = {name: simulation.executed_steps(name)[0] for name in simulation.gateways}
        devices = {name: _devices(simulation, name) for name in simulation.gateways}
    incidents = list(Incident.objects.filter(case__in=ids).values_list("message", flat=True))
    assert incidents == [], incidents
    ran = list(Case.objects.filter(pk__in=ids).order_by("pk"))
    assert [case.status for case in ran] == [CaseStatus.COMPLETED] * cases
    pattern = read_pattern(document)
    for case in ran:
        case_trace = [event for event in trace if event["case"] == case.pk]
        assert case_trace[-1]["event"] == "case-completed"
        check_trace(pattern, case_trace)
    # The simulators counted one execution per step job: nothing ran twice, nothing was lost.
    steps = Job.objects.filter(case__in=ids, kind=WorkItemKind.STEP)
    assert set(steps.values_list("state", flat=True)) == {JobState.SUCCEEDED}
    assert sum(executions.values()) == steps.count()
    return Run(document, ran, trace, executions, devices)


def _devices(simulation: Simulation, name: str) -> dict[str, Any]:
    driver = simulation.cobot(name)
    paths = ("LinearAxis/Position", "Display/Text", "PlacePosition/Free")
    return {path: driver.read(f"Devices/{path}") for path in paths}


def _write(simulation: Simulation, cobot: str, values: dict[str, str]) -> None:
    simulation.cobot(cobot).write({f"Devices/{path}": value for path, value in values.items()})


def _cobot_jobs(cases: list[Case]) -> Iterator[tuple[int, list[Job]]]:
    """Each cobot's jobs of these cases, in the order they ran (device calls are their devices')."""
    jobs = (
        Job.objects.filter(case__in=cases, cobot__isnull=False)
        .select_related("work_item")
        .order_by("started_at")
    )
    for cobot in sorted({job.cobot_id for job in jobs if job.cobot_id is not None}):
        yield cobot, [job for job in jobs if job.cobot_id == cobot]


def test_every_use_case_is_published_sound_with_its_declared_pattern() -> None:
    stems = sorted(path.stem for path in USE_CASES.glob("*.json"))
    assert stems == [
        "1_spot_taping",
        "2_extended_spot_taping",
        "2b_extended_spot_taping_queue_variant",
        "3_pick_and_place",
        "4_quality_inspection",
        "4b_quality_inspection_rechecks_while_homing_variant",
        "5_polishing",
        "5b_polishing_one_line_behind_variant",
        "6_fixture",
        "7_collaborative_assembly",
    ]
    for stem in stems:
        document = load(stem)
        report = check_document(document)
        assert report.valid, (stem, [issue.message for issue in report.errors])
        assert report.sound is True
        if stem == "2_extended_spot_taping":
            # Two processes sharing the cobots: each is synchronized, the whole none of the four.
            assert "declared_pattern" not in document
            assert [issue.code for issue in report.warnings] == ["no-pattern"]
        elif stem == "4_quality_inspection":
            # The thesis' own: its inspectors never share an area, so it has no constraints and
            # counts as cooperation only for that reason, which the check says.
            assert document["declared_pattern"] in report.patterns
            assert [w.code for w in report.warnings] == ["vacuous-pattern"], report.warnings
        else:
            assert list(report.patterns) == [document["declared_pattern"]]
            assert report.warnings == ()
        if "variant" in stem:
            assert "hrc's" in document["name"], stem
            assert "variant" in document["name"], stem


@pytest.mark.django_db(transaction=True)
def test_spot_taping_tapes_four_harnesses_in_two_cycles_the_pedal_moving_the_axis(
    tmp_path: Path, start_worker: Callable[..., WorkerProcess]
) -> None:
    run = run_use_case("1_spot_taping", tmp_path, start_worker, workers=2)

    [case] = run.cases
    assert (case.data["cycle"], case.data["harnesses"], case.data["last_cycle"]) == (2, 4, True)
    done = run.completed(case)
    # Two cycles: each cobot tapes both spots of its workpiece twice.
    assert done["tc_tape_L1"] == done["tc_tape_L2"] == done["tc_tape_R1"] == done["tc_tape_R2"] == 2
    assert run.executions == {"cL": 4, "cR": 4}
    # The axis is the left cobot's device; each pedal moved it once; it ends on the left.
    pedals = sum(n for task, n in done.items() if task.startswith("to_pedal"))
    moves = sum(n for task, n in done.items() if task.startswith("tc_axis"))
    assert pedals == moves == 9
    assert run.devices["cL"]["LinearAxis/Position"] == "left"
    assert run.devices["cR"]["LinearAxis/Position"] == "left"  # the right cell's axis: unused
    # The axis is a device actor of its own lane: its moves wait in its queue, not a cobot's.
    axis_moves = Job.objects.filter(case=case, work_item__task__startswith="tc_axis")
    assert {(job.device.kind if job.device else None) for job in axis_moves} == {"linear-axis"}
    assert not axis_moves.filter(cobot__isnull=False).exists()


@pytest.mark.django_db(transaction=True)
def test_extended_spot_taping_two_processes_take_turns_on_the_cobots_told_by_messages(
    tmp_path: Path, start_worker: Callable[..., WorkerProcess]
) -> None:
    run = run_use_case("2_extended_spot_taping", tmp_path, start_worker, workers=2)

    [case] = run.cases
    assert (case.data["cycle_1"], case.data["harnesses_1"]) == (2, 4)
    assert (case.data["cycle_2"], case.data["harnesses_2"]) == (2, 4)
    assert run.executions == {"c1": 8, "c2": 8}  # four spots for each operator on each cobot
    # Every message the processes sent each other, the case itself took, and only it.
    messages = Message.objects.filter(sent_from_case=case)
    assert messages.count() == 16  # 2 cycles × (3 + 3 syncs, last_cycle), and 2 between them
    assert set(messages.values_list("case", flat=True)) == {case.pk}
    assert not messages.filter(consumed_at__isnull=True).exists()
    sent = case.events.filter(type=EventType.MESSAGE_SENT)
    assert {event.detail["message"] for event in sent} == set(
        messages.values_list("message_id", flat=True)
    )
    assert {event.detail["correlation"]["case"] for event in sent} == {case.pk}
    # Each step job ran after the one before it on its cobot had ended.
    for cobot, jobs in _cobot_jobs(run.cases):
        for before, after in itertools.pairwise(jobs):
            assert before.ended_at is not None
            assert after.started_at is not None
            assert before.ended_at <= after.started_at, f"cobot {cobot}: {before.pk}, {after.pk}"
    # Each operator's linear axis is a device of its own: its moves wait in its own queue.
    axes = Job.objects.filter(case=case, device__isnull=False).select_related("work_item")
    by_device = {
        device: {job.work_item.task for job in axes if job.device_id == device}
        for device in {job.device_id for job in axes}
    }
    assert sorted(by_device.values(), key=sorted) == [
        {f"p1_axis_{k}" for k in range(5)},
        {f"p2_axis_{k}" for k in range(5)},
    ]
    assert all(job.cobot_id is None for job in axes)


@pytest.mark.django_db(transaction=True)
def test_extended_spot_taping_queue_variant_shares_the_cobots_between_two_cases(
    tmp_path: Path, start_worker: Callable[..., WorkerProcess]
) -> None:
    run = run_use_case(
        "2b_extended_spot_taping_queue_variant", tmp_path, start_worker, cases=2, workers=2
    )

    first, second = run.cases
    assert first.data["workspace"] == 0
    assert second.data["workspace"] == 1
    for case in run.cases:
        assert (case.data["cycle"], case.data["harnesses"]) == (2, 4)
    # Operator 2's case: its own operator, the cobots swapped.
    assert first.actor_mapping["o"] != second.actor_mapping["o"]
    assert first.actor_mapping["cL"]["cobot"] == second.actor_mapping["cR"]["cobot"]
    assert first.actor_mapping["cR"]["cobot"] == second.actor_mapping["cL"]["cobot"]
    assert run.executions == {"cL": 8, "cR": 8}  # four spots for each operator on each cobot
    # Each operator's axis is their own left cobot's cell's.
    assert run.devices["cL"]["LinearAxis/Position"] == run.devices["cR"]["LinearAxis/Position"]

    # The trace: on each cobot, the tasks of both cases one after another, never two at once,
    # the cobot going back and forth between the two operators' workspaces.
    cobot_of = {
        (case.pk, actor): binding["cobot"]
        for case in run.cases
        for actor, binding in case.actor_mapping.items()
        if "cobot" in binding
    }
    workspace_of = {case.pk: case.data["workspace"] for case in run.cases}
    running: dict[int, tuple[int, str] | None] = {}
    served: dict[int, list[int]] = {}
    for event in run.trace:
        cobot = cobot_of.get((event["case"], event["actor"]))
        if cobot is None or event["task"].startswith("tc_axis"):
            continue  # an axis move runs in the axis's own queue, beside the cobot's steps
        if event["event"] == "task-started":
            assert running.get(cobot) is None, f"two tasks at once on cobot {cobot}: {event}"
            running[cobot] = (event["case"], event["task"])
            if event["task"].startswith("tc_tape"):
                served.setdefault(cobot, []).append(workspace_of[event["case"]])
        elif event["event"] == "task-completed":
            assert running.get(cobot) == (event["case"], event["task"]), event
            running[cobot] = None
    assert len(served) == 2
    for cobot, workspaces in served.items():
        assert Counter(workspaces) == {0: 4, 1: 4}
        switches = sum(a != b for a, b in itertools.pairwise(workspaces))
        assert switches >= 3, f"cobot {cobot} served {workspaces}: not alternating"
    # The jobs say the same: per cobot, each ran after the one before had ended.
    for cobot, jobs in _cobot_jobs(run.cases):
        for before, after in itertools.pairwise(jobs):
            assert before.ended_at is not None
            assert after.started_at is not None
            assert before.ended_at <= after.started_at, f"cobot {cobot}: {before.pk}, {after.pk}"
        assert {job.command.get("workspace") for job in jobs if job.kind == "step"} == {0, 1}


@pytest.mark.django_db(transaction=True)
def test_pick_and_place_places_the_parts_waits_for_the_place_position_and_calls_the_operator(
    tmp_path: Path, start_worker: Callable[..., WorkerProcess]
) -> None:
    def scene(simulation: Simulation) -> None:
        # A part in the box, the place position occupied when the cobot first gets there.
        _write(simulation, "c", {
            "PartDetection/NextResult": "0.1 0.2 0.05 0 0 0",
            "PlacePosition/NextResult": "occupied",
        })  # fmt: skip

    run = run_use_case("3_pick_and_place", tmp_path, start_worker, before=scene)

    [case] = run.cases
    done = run.completed(case)
    assert case.data["placed"] == done["tc_place"] >= 1
    assert done["tc_scan"] == case.data["placed"] + 1  # the last scan found nothing
    assert done["tc_wait_free"] >= 1  # it waited beside the occupied place position
    assert case.data["box_empty"] is True
    assert run.devices["c"]["Display/Text"] == "The part box is empty: please check it."
    # The operator's process waited for the call: nothing of theirs before it.
    trace = run.case_trace(case)
    called = next(
        i
        for i, e in enumerate(trace)
        if (e["task"], e["event"]) == ("tc_call_operator", "task-completed")
    )
    assert all(e["actor"] != "o" for e in trace[:called])
    assert [e["task"] for e in trace[called + 1 :] if e["event"] == "task-completed"] == [
        "to_check_box",
        "to_box_aside",
        "to_new_box",
    ]


@pytest.mark.django_db(transaction=True)
def test_quality_inspection_decides_all_twelve_spots_the_rechecks_by_the_operator(
    tmp_path: Path, start_worker: Callable[..., WorkerProcess]
) -> None:
    def scene(simulation: Simulation) -> None:
        _write(simulation, "c1", {"Inspection/NextResult": "unsure"})  # BackLeftBot_1
        _write(simulation, "c2", {"Inspection/NextResult": "defect"})  # BackRightBot_1

    run = run_use_case("4_quality_inspection", tmp_path, start_worker, workers=2, before=scene)

    [case] = run.cases
    results = case.data["results"]
    spots = [
        *case.data["manual_spots"],
        *(spot["name"] for spot in case.data["c1_spots"] + case.data["c2_spots"]),
    ]
    assert len(spots) == 12
    assert sorted(result["spot"] for result in results) == sorted(spots)
    assert {result["result"] for result in results} <= {"OK", "NOK"}
    assert case.data["recheck"] == []
    by = {result["spot"]: result for result in results}
    assert by["BackLeftBot_1"]["by"] == "o (recheck)"
    assert by["BackRightBot_1"] == {"spot": "BackRightBot_1", "result": "NOK", "by": "c2"}
    assert {by[spot]["by"] for spot in case.data["manual_spots"]} == {"o"}
    done = run.completed(case)
    rechecked = [r for r in results if r["by"] == "o (recheck)"]
    assert done["to_recheck"] == done["tc1_show_recheck"] == len(rechecked) >= 1
    assert run.devices["c1"]["Display/Text"].startswith("Please recheck ")
    assert run.executions == {"c1": 5, "c2": 5}  # four spots and home each
    # As in the thesis, the rechecks come after all three inspectors are done, homes included.
    trace = run.case_trace(case)
    last_home = max(
        i for i, e in enumerate(trace)
        if e["task"] in ("tc1_home", "tc2_home") and e["event"] == "task-completed"
    )  # fmt: skip
    first_recheck = min(
        i for i, e in enumerate(trace)
        if e["task"] in ("tc1_show_recheck", "to_recheck") and e["event"] == "task-started"
    )  # fmt: skip
    assert last_home < first_recheck


@pytest.mark.django_db(transaction=True)
def test_polishing_the_operator_follows_the_cobot_one_line_behind_in_its_area(
    tmp_path: Path, start_worker: Callable[..., WorkerProcess]
) -> None:
    run = run_use_case("5_polishing", tmp_path, start_worker)

    [case] = run.cases
    assert case.data["lines_checked"] == 6
    assert run.executions == {"c": 7}  # six lines and home
    trace = run.case_trace(case)
    at = {(e["task"], e["event"]): i for i, e in enumerate(trace)}
    overlapping = beside = 0
    for line in range(1, 7):
        # check_trace has kept the time constraint; here the lag itself: line k is checked
        # only after the cobot is done with it, and (but for the last) while it polishes k+1.
        assert at[(f"tc_line{line}", "task-completed")] < at[(f"to_line{line}", "task-started")]
        if line < 6:
            next_done = at[(f"tc_line{line + 1}", "task-completed")]
            overlapping += at[(f"to_line{line}", "task-started")] < next_done
            # Both in the area at once (the operator may be done before the cobot starts).
            beside += (
                at[(f"to_line{line}", "task-started")] < next_done
                and at[(f"tc_line{line + 1}", "task-started")] < at[(f"to_line{line}", "task-completed")]
            )  # fmt: skip
    assert overlapping >= 3
    # Cooperation: beside the operator's line k the cobot polishes line k + 1 slowly, once.
    slowed = Interruption.objects.filter(case=case, mode="slow")
    assert slowed.count() == beside
    assert all(i.ended_at is not None for i in slowed)


@pytest.mark.django_db(transaction=True)
def test_fixture_mounts_all_six_parts_in_the_order_the_operator_chooses(
    tmp_path: Path, start_worker: Callable[..., WorkerProcess]
) -> None:
    run = run_use_case("6_fixture", tmp_path, start_worker)

    [case] = run.cases
    # The simulated operator's choices (the form's examples): the third was mounted already.
    order = ["top right", "bottom left", "top left", "bottom right", "top middle", "bottom middle"]
    assert case.data["mounted"] == order
    done = run.completed(case)
    assert (done["to_choose"], done["tc_say_taken"], done["to_mount"]) == (7, 1, 6)
    holds = Job.objects.filter(case=case, work_item__task="tc_hold").order_by("started_at")
    positions = case.data["positions"]
    assert [job.command["workspace"] for job in holds] == [positions[name] for name in order]
    assert run.executions == {"c": 13}  # six picks, six holds, home


@pytest.mark.django_db(transaction=True)
def test_collaborative_assembly_reworks_a_plate_whose_screws_the_camera_finds_missing(
    tmp_path: Path, start_worker: Callable[..., WorkerProcess]
) -> None:
    def scene(simulation: Simulation) -> None:
        # A stranger looks first; the first plate checked shows two of its four screws.
        _write(simulation, "c", {
            "Recognition/NextFace": "no",
            "Recognition/NextScrews": "2",
        })  # fmt: skip

    run = run_use_case("7_collaborative_assembly", tmp_path, start_worker, before=scene)

    [case] = run.cases
    assert case.data["current"] == len(case.data["tasks"]) == 13
    assert case.data["authorized"] is True
    assert case.data["reworks"] >= 1
    done = run.completed(case)
    assert done["tc_refuse"] >= 1  # the stranger was refused, the operator then recognised
    assert done["to_fit"] == done["tc_rework_hold"] == case.data["reworks"]
    assert done["tc_count"] == 3 + case.data["reworks"]  # every look again after a rework
    assert done["to_perform"] == done["tc_perform"] == 9  # the nine tasks done together
    trace = run.case_trace(case)
    first_count = next(i for i, e in enumerate(trace) if e["task"] == "tc_count")
    rework = next(i for i, e in enumerate(trace) if e["task"] == "to_fit")
    recount = next(i for i, e in enumerate(trace) if e["task"] == "tc_present" and i > rework)
    assert first_count < rework < recount  # the rework path: count, fit, show again
    assert run.devices["c"]["Display/Text"] == "Thank you for collaborating"
    steps = Job.objects.filter(case=case, kind="step").order_by("started_at")
    numbers = [job.command["number"] for job in steps]
    assert numbers[numbers.index(5) + 1] == 1  # after the failed look at the bottom: hold (1)
