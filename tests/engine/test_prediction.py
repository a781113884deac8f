"""Predicting a pattern by simulation: the runtime's rules (constraints, queues, holds, shared
areas, choices) applied to many cases, with exact times where the task times are fixed."""

import copy
import json
from typing import Any

import pytest

from hrc.engine import read_pattern
from hrc.engine.durations import DurationError, Fixed, Lognormal, Triangular
from hrc.engine.prediction import CaseVariant, Scenario, predict, scenario_from_dict
from hrc.engine.prediction_report import Prediction
from hrc.engine.runtime import CaseNet
from hrc_gateway.sim.timing import SimulatedPlant
from tests.engine.builders import EXAMPLES, document, guarded_task, process, with_keys

Doc = dict[str, Any]
USE_CASES = sorted((EXAMPLES / "use_cases").glob("*.json"))


def _predict(doc: Doc, **times: float) -> Prediction:
    """One case, each task its fixed time in seconds, the trace on."""
    return _run(doc, Scenario(cases=1, durations=_fixed(**times), trace=True))


def _run(doc: Doc, scenario: Scenario) -> Prediction:
    return predict(CaseNet(read_pattern(doc)), scenario)


def _fixed(**times: float) -> dict[str, Fixed]:
    return {task: Fixed(seconds) for task, seconds in times.items()}


def _trace(prediction: Prediction, case: int = 0) -> list[tuple[float, str, str]]:
    return [(e.at, e.event, e.task) for e in prediction.trace if e.case == case]


def _lanes(*constraints: tuple[str, str, str], interrupt: str | None = None) -> Doc:
    """An AND-split into a cobot lane (tc0 → tc1) and an operator lane (to0 → to1), joined."""
    lanes = process(
        "N",
        "p1 t1 p2 tc0 p3 tc1 p4 t2 p9",
        "t1 p5 to0 p6 to1 p7 t2",
        performers={"tc0": "c", "tc1": "c", "to0": "o", "to1": "o"},
    )
    data = document(lanes, constraints=list(constraints))
    if interrupt is not None:
        data["constraints"][0]["interrupt"] = interrupt
    return data


# Sequences, splits, the report's figures ----------------------------------------------------


def test_a_sequence_takes_the_sum_of_its_tasks_and_each_starts_as_the_last_completes() -> None:
    doc = document(
        process("N", "p1 to1 p2 tc1 p3 to2 p4", performers={"to1": "o", "tc1": "c", "to2": "o"})
    )

    prediction = _predict(doc, to1=3, tc1=5, to2=2)

    assert _trace(prediction) == [
        (0, "start", "to1"),
        (3, "complete", "to1"),
        (3, "start", "tc1"),
        (8, "complete", "tc1"),
        (8, "start", "to2"),
        (10, "complete", "to2"),
    ]
    assert prediction.cycle_time is not None
    assert prediction.cycle_time.p50 == prediction.cycle_time.p99 == 10
    assert [step.task for step in prediction.critical_path] == ["to1", "tc1", "to2"]
    assert [step.worked for step in prediction.critical_path] == [3, 5, 2]
    assert prediction.bottleneck == "tc1"


def test_cases_one_at_a_time_give_throughput_and_utilisation_over_the_span() -> None:
    doc = document(process("N", "p1 to1 p2 tc1 p3", performers={"to1": "o", "tc1": "c"}))

    prediction = _run(doc, Scenario(cases=4, durations=_fixed(to1=1, tc1=3)))

    assert prediction.completed == 4
    assert prediction.span_seconds == 16
    assert prediction.throughput_per_hour == 4 / 16 * 3600
    assert prediction.actor("c").utilisation == 0.75
    assert prediction.actor("o").utilisation == 0.25
    assert prediction.task("tc1").mean_duration == 3
    assert prediction.task("tc1").critical_share == 0.75


def test_the_lanes_of_a_parallel_split_start_together_and_the_longer_ends_the_case() -> None:
    prediction = _predict(_lanes(), tc0=4, tc1=4, to0=1, to1=2)

    assert _trace(prediction)[:4] == [
        (0, "start", "tc0"),  # a cobot takes its step before a person takes a task
        (0, "start", "to0"),
        (1, "complete", "to0"),
        (1, "start", "to1"),
    ]
    assert prediction.cycle_time is not None
    assert prediction.cycle_time.p50 == 8
    assert [step.task for step in prediction.critical_path] == ["tc0", "tc1"]


# The constraints, as the runtime applies them -----------------------------------------------


def test_a_time_constraint_offers_its_second_task_only_once_the_first_has_completed() -> None:
    prediction = _predict(_lanes(("tc0", "to1", "time")), tc0=5, tc1=1, to0=1, to1=2)

    trace = _trace(prediction)
    assert (1, "complete", "to0") in trace
    assert (5, "start", "to1") in trace  # not at 1, when its lane reached it
    assert prediction.task("to1").mean_wait == 0  # offered at 5: it did not wait for a person
    assert [step.task for step in prediction.critical_path] == ["tc0", "to1"]


def test_a_func_constraint_starts_the_supported_task_while_its_supporter_runs_and_holds_it() -> (
    None
):
    # tc1 (the cobot: the supporter) supports to1: to1 starts once tc1 has started, and tc1,
    # done at 6, completes only when to1 has, at 9.
    prediction = _predict(_lanes(("tc1", "to1", "func")), tc0=4, tc1=2, to0=1, to1=5)

    trace = _trace(prediction)
    assert (4, "start", "to1") in trace  # to0 completed at 1, but tc1 started at 4
    assert trace.index((9, "complete", "to1")) < trace.index((9, "complete", "tc1"))
    assert prediction.actor("c").busy_seconds == 6
    assert prediction.actor("c").held_seconds == 3
    assert [s.task for s in prediction.critical_path] == ["tc0", "tc1", "to1"]


def test_an_operator_whose_completion_a_func_constraint_holds_completes_with_the_cobot() -> None:
    # The operator's task supports the cobot's (to0 → tc1, the cobot's task is the supporter
    # where exactly one is a cobot's: so swap the roles with two operator tasks).
    doc = document(
        process(
            "N",
            "p1 t1 p2 ta p3 t2 p9",
            "t1 p4 tb p5 t2",
            performers={"ta": "o1", "tb": "o2"},
        ),
        constraints=[("ta", "tb", "func")],
    )

    prediction = _predict(doc, ta=1, tb=4)

    trace = _trace(prediction)
    assert (0, "start", "tb") in trace
    assert trace.index((4, "complete", "tb")) < trace.index((4, "complete", "ta"))
    assert prediction.task("ta").mean_duration == 4  # its person held on until tb was done


def test_a_func_hold_keeps_another_cases_step_off_the_cobot_until_it_ends() -> None:
    doc = document(
        process(
            "N", "p1 t1 p2 tc1 p3 t2 p9", "t1 p4 to1 p5 t2", performers={"tc1": "c", "to1": "o"}
        ),
        constraints=[("tc1", "to1", "func")],
    )
    # tc1 is done at 2 and held until to1 completes at 5: case 1's tc1 waits till then, not
    # only till 2 (the cobot holds case 0's part).
    scenario = Scenario(cases=2, parallel=2, durations=_fixed(tc1=2, to1=5), trace=True)

    prediction = _run(doc, scenario)

    assert _trace(prediction, 1)[0] == (5, "start", "tc1")
    assert prediction.actor("c").held_seconds == 6
    assert prediction.actor("c").waiting_seconds == 5


def test_an_operator_in_a_shared_area_pauses_the_cobot_until_the_operators_task_completes() -> None:
    # tc1 (10 s) starts at 0 beside to0 (4 s), which pauses it: it resumes at 4 and ends at 14.
    doc = _lanes(("tc0", "to0", "space"))
    prediction = _predict(doc, tc0=10, tc1=0, to0=4, to1=0)

    assert (14, "complete", "tc0") in _trace(prediction)
    assert prediction.actor("c").interrupted_seconds == 4
    assert prediction.cycle_time is not None
    assert prediction.cycle_time.p50 == 14


def test_a_handover_delays_each_tasks_work_and_the_area_is_entered_after_it() -> None:
    # Each task starts, then works after 1 s: tc0 works 1–11; to0 starts at 0 and enters the
    # area at 1, pausing tc0 until it completes at 5; tc0 ends at 15, tc1 (0 s) at 16.
    doc = _lanes(("tc0", "to0", "space"))
    times = _fixed(tc0=10, tc1=0, to0=4, to1=0)
    prediction = _run(doc, Scenario(cases=1, durations=times, trace=True, handover=1.0))

    trace = _trace(prediction)
    assert (0, "start", "to0") in trace
    assert (5, "complete", "to0") in trace
    assert (15, "complete", "tc0") in trace
    assert prediction.actor("c").interrupted_seconds == 4
    assert prediction.cycle_time is not None
    assert prediction.cycle_time.p50 == 16


def test_a_slowed_cobot_goes_on_at_a_tenth_of_its_speed_while_the_operator_works() -> None:
    doc = _lanes(("tc0", "to0", "space"), interrupt="slow")
    prediction = _predict(doc, tc0=10, tc1=0, to0=4, to1=0)

    # 0.4 s of its work done in the 4 s beside the operator, 9.6 s after.
    [end] = [at for at, event, task in _trace(prediction) if (event, task) == ("complete", "tc0")]
    assert end == pytest.approx(13.6)


def test_a_cobot_step_waits_for_an_operator_already_in_the_shared_area() -> None:
    # tc1 is offered at 2 while to0 works in the area until 6: it waits, then runs 6–16.
    doc = _lanes(("tc1", "to0", "space"))
    prediction = _predict(doc, tc0=2, tc1=10, to0=6, to1=0)

    trace = _trace(prediction)
    assert (6, "start", "tc1") in trace
    assert (16, "complete", "tc1") in trace
    assert prediction.actor("c").interrupted_seconds == 0


def test_the_second_operator_into_a_shared_area_is_kept_out_until_the_first_is_done() -> None:
    doc = document(
        process("N", "p1 t1 p2 ta p3 t2 p9", "t1 p4 tb p5 t2", performers={"ta": "o1", "tb": "o2"}),
        constraints=[("ta", "tb", "space")],
    )
    prediction = _predict(doc, ta=3, tb=2)

    assert _trace(prediction) == [
        (0, "start", "ta"),
        (3, "complete", "ta"),
        (3, "start", "tb"),
        (5, "complete", "tb"),
    ]


# Queues and teams -----------------------------------------------------------------------------


def test_parallel_cases_queue_for_one_cobot_first_come_first_served() -> None:
    doc = document(process("N", "p1 tc1 p2", performers={"tc1": "c"}))

    prediction = _run(doc, Scenario(cases=3, parallel=3, durations=_fixed(tc1=5), trace=True))

    starts = [(e.case, e.at) for e in prediction.trace if e.event == "start"]
    assert starts == [(0, 0), (1, 5), (2, 10)]
    assert prediction.actor("c").waiting_seconds == 15
    assert prediction.actor("c").waited == 2
    assert prediction.cycle_time is not None
    assert prediction.cycle_time.max == 15


def test_two_cobot_actors_standing_in_for_one_cobot_share_its_queue() -> None:
    doc = document(
        process("N", "p1 t1 p2 ta p3 t2 p9", "t1 p4 tb p5 t2", performers={"ta": "c1", "tb": "c2"})
    )
    one_cobot = (CaseVariant("one cobot", actors={"c2": "c1"}),)
    scenario = Scenario(cases=1, durations=_fixed(ta=5, tb=3), variants=one_cobot, trace=True)

    prediction = _run(doc, scenario)

    assert _trace(prediction) == [
        (0, "start", "ta"),  # offered first (net order), so first in the queue
        (5, "complete", "ta"),
        (5, "start", "tb"),
        (8, "complete", "tb"),
    ]
    assert [load.actor for load in prediction.actors] == ["c1"]


def test_one_person_serves_two_parallel_cases_one_after_the_other() -> None:
    doc = document(process("N", "p1 to1 p2", performers={"to1": "o"}))

    one = _run(doc, Scenario(cases=2, parallel=2, durations=_fixed(to1=4)))
    two = _run(doc, Scenario(cases=2, parallel=2, durations=_fixed(to1=4), people={"o": 2}))
    unlimited = _run(doc, Scenario(cases=2, parallel=2, durations=_fixed(to1=4), people={"o": None}))  # fmt: skip

    assert one.actor("o").waiting_seconds == 4
    assert one.actor("o").waiting_per_case == 2
    assert one.actor("o").utilisation == 1
    assert one.cycle_time is not None
    assert one.cycle_time.max == 8
    assert two.actor("o").waiting_seconds == unlimited.actor("o").waiting_seconds == 0
    assert two.actor("o").utilisation == 1  # 8 busy person-seconds over 2 persons × 4 s
    assert unlimited.actor("o").utilisation == 2  # two busy at once on average


# Choices ---------------------------------------------------------------------------------------


def _choice() -> Doc:
    return document(
        process("N", "p1 x1 p2 ta p9", "p1 x2 p3 tb p9", performers={"ta": "o", "tb": "o"})
    )


def test_weights_decide_a_choice_in_their_proportion() -> None:
    scenario = Scenario(cases=4000, weights={"x1": 3, "x2": 1}, durations=_fixed(ta=1, tb=1))

    prediction = _run(_choice(), scenario)

    assert prediction.task("ta").runs / 4000 == pytest.approx(0.75, abs=0.02)
    assert prediction.task("ta").runs + prediction.task("tb").runs == 4000


def test_guards_decide_a_choice_without_weights_and_an_unguarded_one_is_drawn_evenly() -> None:
    guarded = with_keys(_choice(), x1={"guard": "data.left"}, x2={"guard": "not data.left"})
    guarded["data"] = {"left": False}

    by_guard = _run(guarded, Scenario(cases=100))
    drawn = _run(_choice(), Scenario(cases=2000))

    assert [load.task for load in by_guard.tasks] == ["tb"]
    assert drawn.task("ta").runs / 2000 == pytest.approx(0.5, abs=0.04)


def test_a_loop_left_on_an_operators_answer_runs_as_often_as_the_examples_say() -> None:
    # The operator says "again" twice, then "done": the loop's task runs three times a case.
    loop = document(process("N", "p0 x0 p1 to1 p2 x1 p1", "p2 x2 p3", performers={"to1": "o"}))
    form: Doc = {
        "type": "object",
        "required": ["again"],
        "properties": {"again": {"type": "boolean", "examples": [True, True, False]}},
    }
    loop = with_keys(
        loop,
        to1={"task": {"form": form, "outputs": {"again": "result.again"}}},
        x1={"guard": "data.again"},
        x2={"guard": "not data.again"},
    )

    prediction = _run(loop, Scenario(cases=5, durations=_fixed(to1=1)))

    assert prediction.task("to1").runs == 15
    assert prediction.cycle_time is not None
    assert prediction.cycle_time.p50 == 3


# Repeatability, timers, cancelling, cases that cannot end --------------------------------------


def test_the_same_seed_gives_the_same_prediction_and_another_seed_other_samples() -> None:
    doc = _lanes(("tc0", "to1", "time"))
    times = {t: Triangular(1, 2, 6) for t in ("tc0", "tc1", "to0", "to1")}

    def run(seed: int) -> dict[str, Any]:
        scenario = Scenario(cases=200, parallel=3, seed=seed, durations=times, trace=True)
        return _run(doc, scenario).as_dict()

    first, again, other = run(7), run(7), run(8)

    assert json.dumps(first) == json.dumps(again)
    assert first["cycle_time"] != other["cycle_time"]
    assert first["trace"] != other["trace"]


def test_a_timer_rings_after_its_time_and_the_case_goes_on() -> None:
    doc = with_keys(
        document(process("N", "p1 to1 p2 xt p3 to2 p4", performers={"to1": "o", "to2": "o"})),
        xt={"timer": "PT1M"},
    )

    prediction = _predict(doc, to1=2, to2=3)

    assert (62, "start", "to2") in _trace(prediction)
    assert prediction.cycle_time is not None
    assert prediction.cycle_time.p50 == 65


def test_a_cancelled_step_ends_its_case_but_runs_on_on_its_cobot() -> None:
    # The timer (10 s) cancels ta (30 s): case 0 ends at 10, its step runs on till 30. Case 1,
    # started at 10, queues ta behind it; its own timer withdraws ta at 20, never started.
    doc = guarded_task(["ta", "pt", "pd"])

    prediction = _run(doc, Scenario(cases=2, durations=_fixed(ta=30), trace=True))

    assert prediction.completed == 2
    assert prediction.cycle_time is not None
    assert prediction.cycle_time.max == 10
    assert _trace(prediction, 0) == [(0, "start", "ta")]
    assert _trace(prediction, 1) == []
    assert prediction.actor("c").busy_seconds == 30
    assert prediction.tasks == ()  # ta never completed
    assert prediction.critical_path == ()


def test_a_silent_cancel_frees_its_operator_in_every_case_not_only_the_first() -> None:
    # xc fires as the cobot's tb (5 s) completes and cancels the operator's ta (30 s), so that
    # the same operator's tc (5 s) starts at once: every case takes 10 s, also those that
    # reach xc where an earlier case did (what that case's firing reached is not replayed).
    performers = {"ta": "o", "tb": "c", "tc": "o"}
    net = process("N", "p0 xf p1 ta p9", "xf p3 tb p4 xc p5 tc p9", performers=performers)
    doc = with_keys(document(net), xc={"cancels": ["ta"]})

    prediction = _run(doc, Scenario(cases=3, durations=_fixed(ta=30, tb=5, tc=5)))

    assert prediction.completed == 3
    assert prediction.cycle_time is not None
    assert prediction.cycle_time.max == 10


def test_a_pattern_that_deadlocks_reports_its_cases_as_stuck_and_ends() -> None:
    # to1 waits for a completion of tc1, which comes after it: nothing can ever start.
    doc = document(
        process("N", "p1 to1 p2 tc1 p3", performers={"to1": "o", "tc1": "c"}),
        constraints=[("tc1", "to1", "time")],
    )

    prediction = _run(doc, Scenario(cases=3))

    assert prediction.completed == 0
    assert prediction.stuck_count == 3
    assert prediction.cycle_time is None
    assert prediction.bottleneck is None
    assert "cannot go on: nothing can start" in prediction.stuck[0].why
    assert prediction.stuck[0].marking == {"p1": 1}


def test_a_step_whose_command_fails_as_it_is_offered_sticks_its_case_with_the_reason() -> None:
    # tc1's poses read an index the data lacks: its command fails when to1 completes.
    doc = with_keys(
        document(process("N", "p1 to1 p2 tc1 p3", performers={"to1": "o", "tc1": "c"})),
        tc1={"task": {"step": {"number": 2, "poses": "=[data.poses[3]]"}}},
    )
    doc["data"] = {"poses": [[0, 0, 0, 0, 0, 0]]}
    scenario = Scenario(cases=2, durations=_fixed(to1=1))

    prediction = predict(CaseNet(read_pattern(doc)), scenario, plant=SimulatedPlant)

    assert prediction.completed == 0
    assert prediction.stuck_count == 2  # each as its to1 completes, the next one after it
    assert [case.at for case in prediction.stuck] == [1, 1]  # into the case, at to1's end
    assert "The configuration of tc1 failed" in prediction.stuck[0].why


def test_a_case_waiting_for_a_message_nobody_sends_is_stuck_where_it_waits() -> None:
    doc = with_keys(
        document(process("N", "p1 to1 p2 xm p3", performers={"to1": "o"})),
        xm={"message": {"name": "part-ready"}},
    )

    prediction = _run(doc, Scenario(cases=5, durations=_fixed(to1=1)))

    assert prediction.completed == 0
    assert prediction.stuck_count == 1  # the one case in flight: no other starts behind it
    assert prediction.stuck[0].at == 1
    assert "waits for the message 'part-ready'" in prediction.stuck[0].why


def test_a_loop_no_answer_leaves_is_stopped_and_reported() -> None:
    loop = document(process("N", "p0 x0 p1 to1 p2 x1 p1", "p2 x2 p3", performers={"to1": "o"}))
    loop = with_keys(loop, x1={"guard": "true"}, x2={"guard": "false"})

    prediction = _run(loop, Scenario(cases=2, max_tasks_per_case=50, durations=_fixed(to1=1)))

    assert prediction.stuck_count == 2
    assert "ran 50 tasks without ending" in prediction.stuck[0].why


# The use cases ---------------------------------------------------------------------------------


@pytest.mark.parametrize("path", USE_CASES, ids=lambda path: path.stem)
def test_every_use_case_simulates_to_completion_against_the_simulated_plant(path: Any) -> None:
    net = CaseNet(read_pattern(json.loads(path.read_text())))

    prediction = predict(net, Scenario(cases=60, parallel=2), plant=SimulatedPlant)

    assert (prediction.completed, prediction.stuck_count) == (60, 0)
    assert prediction.cycle_time is not None
    assert prediction.cycle_time.p50 > 0
    assert prediction.bottleneck is not None
    assert prediction.critical_path
    assert not {t for t in prediction.assumed if net.tasks[t].kind != "operator"}
    json.dumps(prediction.as_dict())


def test_variants_of_the_document_give_each_case_its_own_operator_and_cobots() -> None:
    doc = json.loads((EXAMPLES / "use_cases" / "2b_extended_spot_taping_queue_variant.json").read_text())  # fmt: skip
    alone = copy.deepcopy(doc)
    del alone["simulation"]

    variants = _run(doc, Scenario(cases=2, parallel=2))
    one_operator = _run(alone, Scenario(cases=2, parallel=2))

    assert {load.actor for load in variants.actors if load.kind == "operator"} == {"o", "o2"}
    assert variants.actor("o").waiting_seconds == 0
    assert one_operator.actor("o").waiting_seconds > 0


# A scenario as JSON --------------------------------------------------------------------------


def test_a_scenario_reads_from_json_with_times_people_weights_and_variants() -> None:
    scenario = scenario_from_dict(
        {
            "cases": 50,
            "parallel": 2,
            "seed": 3,
            "durations": {"to1": {"kind": "lognormal", "median": 20, "p90": 30}},
            "operator_default": {"kind": "fixed", "seconds": 12},
            "people": {"o": 2, "o2": None},
            "weights": {"x1": 3, "x2": 1.5},
            "variants": [{"name": "swapped", "actors": {"c1": "c2"}}],
            "trace": True,
            "handover": 0.5,
        }
    )

    assert scenario == Scenario(
        cases=50,
        parallel=2,
        seed=3,
        durations={"to1": Lognormal.from_median_p90(20, 30)},
        operator_default=Fixed(12),
        people={"o": 2, "o2": None},
        weights={"x1": 3.0, "x2": 1.5},
        variants=(CaseVariant("swapped", {}, {"c1": "c2"}),),
        trace=True,
        handover=0.5,
    )
    assert scenario_from_dict({}) == Scenario()


@pytest.mark.parametrize(
    ("data", "message"),
    [
        ({"cases": "many"}, "cases must be a whole number"),
        ({"parallel": 0}, "parallel ≥ 1"),
        ({"durations": {"to1": {"kind": "fixed"}}}, "to1: a fixed time needs 'seconds'"),
        ({"weights": {"x1": -1}}, "weights must be finite numbers ≥ 0"),
        ({"people": {"o": 0}}, "at least one person"),
        ({"handover": -1}, "handover is a finite number of seconds ≥ 0"),
        ({"variants": {"name": "one"}}, "'variants' must be a list"),
        ({"speed": 2}, "a scenario has no 'speed'"),
    ],
)
def test_a_scenario_that_makes_no_sense_is_refused_saying_why(data: Doc, message: str) -> None:
    with pytest.raises((ValueError, DurationError), match=message):
        scenario_from_dict(data)


def test_a_variant_whose_stand_in_is_of_another_type_is_refused() -> None:
    doc = document(process("N", "p1 to1 p2 tc1 p3", performers={"to1": "o", "tc1": "c"}))
    wrong = (CaseVariant("wrong", actors={"o": "c"}),)

    with pytest.raises(ValueError, match="o and c are not both operators"):
        _run(doc, Scenario(cases=1, variants=wrong))
