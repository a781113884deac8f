"""Timers and cancellation regions as the runtime fires them and the check judges them."""

import copy
from typing import Any

import pytest

from hrc.engine import check_document, read_pattern
from hrc.engine.analysis import analyse
from hrc.engine.execution import build_execution_net
from hrc.engine.petri import Marking, Net, NetTransition
from hrc.engine.reduction import reduce_net
from hrc.engine.runtime import CaseNet, NotEnabled
from hrc.engine.tokengame import execution_net_json
from hrc.engine.wording import Names
from tests.engine.builders import document, guarded_task, process, with_keys

Doc = dict[str, Any]


def _without(data: Doc, key: str) -> Doc:
    data = copy.deepcopy(data)
    for net in data["processes"]:
        for transition in net["transitions"]:
            transition.pop(key, None)
    return data


def _timer_or_task() -> Doc:
    """A deferred choice in p1: the operator starts ta, or after a minute xt takes the case to tb."""
    data = document(
        process("N", "p0 x0 p1 ta p2 x2 p9", "p1 xt p3 tb p9", performers={"ta": "o", "tb": "o"})
    )
    return with_keys(data, xt={"timer": "PT1M"})


def _terminate(cancels: bool) -> Doc:
    """An AND-split into ta and tb; after ta, xend ends the whole process (a terminate end
    event), or xgo waits for tb at the join tj."""
    data = document(
        process(
            "N",
            "p1 t1 p2 ta p3 xgo p7 tj p9",
            "t1 p4 tb p5 xb p6 tj",
            "p3 xend p9",
            performers={"ta": "o", "tb": "c"},
        )
    )
    if cancels:
        net = data["processes"][0]
        everything = [p["id"] for p in net["places"]] + [t["id"] for t in net["transitions"]]
        with_keys(data, xend={"cancels": everything})
    return data


# Timers at run time -----------------------------------------------------------------------


def test_settle_never_fires_a_timer_transition() -> None:
    net = CaseNet(read_pattern(_timer_or_task()))

    marking, fired = net.settle(net.initial, {})

    assert fired == ["x0"]
    assert marking == Marking({"p1": 1})
    assert net.waiting_timers(marking) == [("xt", 60_000)]
    assert net.settle(marking, {}) == (marking, [])


def test_ring_fires_an_enabled_timer_and_the_case_goes_on() -> None:
    net = CaseNet(read_pattern(_timer_or_task()))
    marking, _ = net.settle(net.initial, {})

    after = net.ring(marking, "xt")

    assert after == Marking({"p3": 1})
    assert net.startable(after) == ["tb"]
    assert net.waiting_timers(after) == []


def test_ring_refuses_a_timer_that_is_not_enabled() -> None:
    net = CaseNet(read_pattern(_timer_or_task()))

    assert net.waiting_timers(net.initial) == []
    with pytest.raises(NotEnabled, match="the timer of xt: it waits for a token in p1"):
        net.ring(net.initial, "xt")


@pytest.mark.parametrize("transition", ["x0", "x2", "start:ta", "ta"])
def test_ring_fires_only_timer_transitions(transition: str) -> None:
    net = CaseNet(read_pattern(_timer_or_task()))

    with pytest.raises(NotEnabled, match=f"^{transition} has no timer"):
        net.ring(Marking({"p0": 1, "p1": 1, "p2": 1}), transition)


def test_starting_the_task_of_a_deferred_choice_disables_the_timer() -> None:
    net = CaseNet(read_pattern(_timer_or_task()))
    marking, _ = net.settle(net.initial, {})

    started = net.start(marking, "ta")

    assert net.waiting_timers(started) == []
    with pytest.raises(NotEnabled, match="the timer of xt"):
        net.ring(started, "xt")


def test_ringing_the_timer_of_a_deferred_choice_withdraws_the_task() -> None:
    net = CaseNet(read_pattern(_timer_or_task()))
    marking, _ = net.settle(net.initial, {})

    rung = net.ring(marking, "xt")

    assert "ta" not in net.startable(rung)
    with pytest.raises(NotEnabled, match="ta cannot start"):
        net.start(rung, "ta")


# Cancelling at run time -------------------------------------------------------------------


def test_a_cancelled_running_task_can_no_longer_complete() -> None:
    net = CaseNet(read_pattern(guarded_task(["ta", "pt", "pd"])))
    marking, fired = net.settle(net.initial, {})
    assert fired == ["xf"]
    running = net.start(marking, "ta")
    assert running.get("running:ta") == 1
    assert net.waiting_timers(running) == [("xt", 10_000)]

    rung = net.ring(running, "xt")

    assert rung.get("running:ta") == 0
    assert not net.can_complete(rung, "ta")
    with pytest.raises(NotEnabled, match="ta cannot complete: it waits for ta to be running"):
        net.complete(rung, "ta")
    ended, fired = net.settle(rung, {})
    assert fired == ["xto"]
    assert net.is_final(ended)


def test_a_task_that_completes_in_time_ends_the_watch() -> None:
    net = CaseNet(read_pattern(guarded_task(["ta", "pt", "pd"])))
    marking, _ = net.settle(net.initial, {})

    done = net.complete(net.start(marking, "ta"), "ta")
    ended, fired = net.settle(done, {})

    assert fired == ["xok"]
    assert net.is_final(ended)
    assert net.waiting_timers(ended) == []


def test_the_execution_net_resets_the_running_place_of_a_cancelled_task() -> None:
    net = build_execution_net(read_pattern(guarded_task(["ta", "pt", "pd", "xok"])))

    resets = {t.id: t.resets for t in net.transitions}

    # xok is a silent transition: it holds no token, so naming it changes nothing.
    assert resets["xt"] == ("running:ta", "pt", "pd")
    assert {t: r for t, r in resets.items() if r} == {"xt": ("running:ta", "pt", "pd")}


def test_cancelling_a_supporter_withdraws_its_support_too() -> None:
    # ta (the cobot's) supports to (func): while ta runs, to may start; cancelled, it no longer may.
    data = guarded_task(["ta", "pt", "pd", "po", "pq", "to"])
    net = data["processes"][0]
    net["places"] += [{"id": "po"}, {"id": "pq"}]
    net["transitions"].append({"id": "to", "performer": "o"})
    net["arcs"] += [["xf", "po"], ["po", "to"], ["to", "pq"], ["pq", "xok"]]
    net["actors"].append("o")
    data["actors"].append({"id": "o", "type": "operator"})
    data["constraints"] = [{"from": "ta", "to": "to", "type": "func"}]
    case = CaseNet(read_pattern(data))
    marking, _ = case.settle(case.initial, {})
    running = case.start(marking, "ta")
    assert case.can_start(running, "to")

    rung = case.ring(running, "xt")

    assert case.transition("xt").resets == (
        "running:ta",
        "func-start:ta>to",
        "func-done:to>ta",
        "pt",
        "pd",
        "po",
        "pq",
        "running:to",
    )
    assert rung.get("func-start:ta>to") == 0
    assert check_document(data).sound is True


def test_a_reset_empties_a_place_whatever_it_holds_before_the_outputs_arrive() -> None:
    t = NetTransition("x", "x", "silent", (("a", 1),), (("b", 1),), resets=("b", "c"))

    assert t.is_enabled(Marking({"a": 1}))
    assert t.fire(Marking({"a": 2, "b": 3, "c": 5, "d": 1})) == Marking({"a": 1, "b": 1, "d": 1})


# The check ----------------------------------------------------------------------------------


def test_a_timer_is_judged_as_any_silent_transition() -> None:
    sound = _timer_or_task()
    # Without its join, the timer's branch leaves p2 behind: unsound either way.
    unsound = with_keys(
        document(
            process(
                "N", "p0 x0 p1 ta p2 x2 p9", "x0 p4 xt p3 tb p9", performers={"ta": "o", "tb": "o"}
            )
        ),
        xt={"timer": "PT5M"},
    )

    for data, verdict in ((sound, True), (unsound, False)):
        timed, plain = check_document(data), check_document(_without(data, "timer"))
        assert timed.sound is verdict, timed.as_dict()
        # The same findings; only the words differ ("timer xt rings" for "split/join xt fires").
        assert [(e.code, e.elements, e.witness) for e in timed.errors] == [
            (e.code, e.elements, e.witness) for e in plain.errors
        ]


def test_a_terminate_that_cancels_the_running_branch_is_sound() -> None:
    report = check_document(_terminate(cancels=True))

    assert report.errors == (), report.as_dict()
    assert report.sound is True


def test_without_cancels_the_same_terminate_leaves_work_over() -> None:
    report = check_document(_terminate(cancels=False))

    assert report.sound is False
    improper = next(e for e in report.errors if "left over" in e.message)
    assert improper.witness is not None
    assert improper.witness[-1] == "xend"
    # The reduction runs tb's branch on to its join as a whole: p6 is where it waits.
    assert "place p6 still holds 1 token" in improper.message


def test_a_witness_through_a_cancel_replays_and_names_what_it_missed() -> None:
    # xt forgets pd: after ta completes, the timer can still ring and end the case past pd.
    data = guarded_task(["ta", "pt"])
    net = build_execution_net(read_pattern(data))

    improper = next(e for e in check_document(data).errors if "left over" in e.message)

    assert improper.witness == ("xf", "start ta", "complete ta", "xt", "xto")
    assert improper.message == (
        "The case can end with work left over: after split/join xf fires, task ta starts, "
        "task ta completes, timer xt rings and cancels task ta and place pt, split/join xto "
        "fires, the end place has its token while place pd still holds 1 token."
    )
    by_label = {t.label: t for t in net.transitions}
    marking = net.initial
    for label in improper.witness:
        assert by_label[label].is_enabled(marking)
        marking = by_label[label].fire(marking)
    assert marking == Marking({"pd": 1, "p9": 1})


def test_the_cancelled_timer_net_is_sound_and_unsound_without_its_cancels() -> None:
    assert check_document(guarded_task(["ta", "pt", "pd"])).sound is True
    assert check_document(guarded_task([])).sound is False


def test_the_reduction_keeps_a_place_whose_chain_leaves_a_reset_region() -> None:
    # xt empties pt and running:ta but not pd: completing ta takes its token out of the region.
    net = build_execution_net(read_pattern(guarded_task(["ta", "pt"])))

    reduced = reduce_net(net)

    assert "running:ta" in reduced.places
    assert "pt" not in reduced.places  # pt and running:ta are emptied together
    [timer] = [t for t in reduced.transitions if "xt" in t.firings]
    assert timer.resets == ("running:ta",)


def test_a_terminate_region_leaves_the_chains_inside_it_reducible() -> None:
    def reduced_places(cancels: bool) -> tuple[str, ...]:
        return reduce_net(build_execution_net(read_pattern(_terminate(cancels)))).places

    # Both branches collapse into the split, as they do without the terminate's cancels.
    assert (
        reduced_places(cancels=True)
        == reduced_places(cancels=False)
        == (
            "p1",
            "p3",
            "p7",
            "p9",
            "p6",
        )
    )


def test_a_reset_on_the_way_is_no_proof_of_unboundedness() -> None:
    # x puts a token in b and loops back to a, but empties b first: b never holds more than one.
    def arc(*places: str) -> tuple[tuple[str, int], ...]:
        return tuple((place, 1) for place in places)

    net = Net(
        places=("a", "b", "o"),
        transitions=(
            NetTransition("x", "x", "silent", arc("a"), arc("a", "b"), resets=("b",)),
            NetTransition("y", "y", "silent", arc("a", "b"), arc("o")),
        ),
        initial=Marking({"a": 1}),
        final=Marking({"o": 1}),
    )
    growing = Net(
        net.places,
        (NetTransition("x", "x", "silent", arc("a"), arc("a", "b")), net.transitions[1]),
        net.initial,
        net.final,
    )

    assert analyse(net).sound is True
    assert [f.kind for f in analyse(growing).faults] == ["unbounded"]


def test_the_token_game_gets_the_resets() -> None:
    game = execution_net_json(read_pattern(guarded_task(["ta", "pt", "pd"])))

    resets = {t["id"]: t["resets"] for t in game["transitions"]}

    assert resets["xt"] == ["running:ta", "pt", "pd"]
    assert resets["start:ta"] == []


def test_a_firing_sequence_says_a_timer_rings_and_what_a_step_cancels() -> None:
    terminate = Names(read_pattern(_terminate(cancels=True)))
    timed = Names(read_pattern(guarded_task(["ta"])))

    assert timed.firing("silent", "xt") == "timer xt rings and cancels task ta"
    assert timed.firing("silent", "xto") == "split/join xto fires"
    assert terminate.firing("silent", "xend") == (
        "split/join xend fires and cancels place p1, place p2, place p3 and 12 more"
    )
