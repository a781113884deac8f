"""Soundness findings, their witnesses and explanations, the reduction, and the exploration cap."""

from typing import Any

from hrc.engine import check_document, read_pattern
from hrc.engine.analysis import analyse
from hrc.engine.budget import Budget
from hrc.engine.execution import build_execution_net
from hrc.engine.issues import Issue
from hrc.engine.petri import Marking, Net, NetTransition
from hrc.engine.reduction import reduce_net
from tests.engine.builders import document, process, two_lanes


def _errors(data: dict[str, Any]) -> list[tuple[str, str, tuple[str, ...] | None]]:
    return [(e.code, e.message, e.witness) for e in check_document(data).errors]


def test_a_deadlock_comes_with_the_shortest_sequence_and_what_waits_for_what() -> None:
    data = two_lanes([("to1", "tc2", "time"), ("tc3", "to1", "time")])

    code, message, witness = _errors(data)[0]

    assert code == "unsound"
    assert witness == ("t1", "start tc1", "complete tc1")
    assert "start of task tc2 waits for a completion of to1 (time constraint to1 → tc2)" in message
    assert (
        "the start of task to1 waits for a completion of tc3 (time constraint tc3 → to1)" in message
    )


def test_tasks_that_can_never_start_are_named_with_the_constraint_they_need() -> None:
    data = two_lanes([("to1", "tc2", "time"), ("tc3", "to1", "time")])

    dead = next(e for e in check_document(data).errors if "never start" in e.message)

    assert set(dead.elements) == {"tc2", "tc3", "to1", "to2", "t2"}
    assert "the start of task to1 needs a completion of tc3" in dead.message


def test_a_func_constraint_whose_supported_task_comes_later_deadlocks() -> None:
    # tc1 must hold on until to2 is done, but to2 comes after to1, which waits for tc3, after tc1.
    data = two_lanes([("tc1", "to2", "func"), ("tc3", "to1", "time")])

    deadlock = check_document(data).errors[0]

    assert deadlock.witness == ("t1", "start tc1")
    assert (
        "completion of task tc1 waits for to2 to complete (func constraint: tc1 supports to2)"
        in deadlock.message
    )


def test_an_exclusive_branch_without_its_join_ends_with_work_left_over() -> None:
    net = process(
        "N",
        "p1 t1 p2 tc1 p3 t2 p4",
        "t1 p5 to1 p6 t2",
        "p5 to2 p4",
        performers={"tc1": "c", "to1": "o", "to2": "o"},
    )

    errors = check_document(document(net)).errors

    improper = next(e for e in errors if "left over" in e.message)
    assert improper.witness is not None
    assert improper.witness[-1] == "complete to2"
    assert improper.message.endswith(
        "the end place has its token while place p3 still holds 1 token."
    )
    assert improper.elements == ("p3",)


def _marked(data: dict[str, Any], tokens: dict[str, int]) -> dict[str, Any]:
    for place in data["processes"][0]["places"]:
        if place["id"] in tokens:
            place["tokens"] = tokens[place["id"]]
    return data


def _left_over(data: dict[str, Any]) -> Issue:
    return next(e for e in check_document(data).errors if "left over" in e.message)


def test_tokens_left_on_the_end_place_itself_are_named_with_their_count() -> None:
    data = _marked(document(process("N", "p1 t1 p2", performers={"t1": "o"})), {"p2": 100})

    improper = _left_over(data)

    assert improper.message == (
        "The case can end with work left over: right at the start, the end place p2 holds "
        "100 tokens where a finished case leaves 1 token."
    )
    assert improper.elements == ("p2",)


def test_a_place_left_with_many_tokens_says_how_many() -> None:
    net = process("N", "p1 t1 p2 t2 p3", performers={"t1": "o", "t2": "o"})

    improper = _left_over(_marked(document(net), {"p1": 100}))

    assert improper.message.endswith("while place p1 still holds 99 tokens.")
    assert improper.elements == ("p1",)


def test_an_end_place_with_a_token_too_many_and_a_place_beside_it_are_both_named() -> None:
    net = process("N", "p1 t1 p2 t2 p3", performers={"t1": "o", "t2": "o"})

    improper = _left_over(_marked(document(net), {"p1": 1, "p3": 2}))

    assert improper.message == (
        "The case can end with work left over: right at the start, the end place p3 holds "
        "2 tokens where a finished case leaves 1 token and place p1 still holds 1 token."
    )
    assert improper.elements == ("p3", "p1")


def test_a_loop_that_can_never_leave_is_a_livelock_with_its_way_in() -> None:
    # w finishes at once; but after s, a -x-> b -y-> a loops for ever: z, the loop's only way
    # out, needs q, which nothing marks.
    def arc(place: str) -> tuple[tuple[str, int], ...]:
        return ((place, 1),)

    net = Net(
        places=("i", "a", "b", "q", "o"),
        transitions=(
            NetTransition("w", "w", "silent", arc("i"), arc("o")),
            NetTransition("s", "s", "silent", arc("i"), arc("a")),
            NetTransition("x", "x", "silent", arc("a"), arc("b")),
            NetTransition("y", "y", "silent", arc("b"), arc("a")),
            NetTransition("z", "z", "silent", (("b", 1), ("q", 1)), arc("o")),
        ),
        initial=Marking({"i": 1}),
        final=Marking({"o": 1}),
    )

    faults = analyse(net).faults

    # x is the only way on from a, so the reduction fires it right after s.
    assert [(f.kind, f.witness) for f in faults if f.kind == "livelock"] == [
        ("livelock", ("s", "x"))
    ]
    assert [f.transition for f in faults if f.kind == "dead"] == ["z"]
    assert not any(f.kind == "deadlock" for f in faults)


def test_the_unbounded_place_and_the_repeating_firings_are_named() -> None:
    data = two_lanes([])
    net = data["processes"][0]
    net["transitions"].append({"id": "t3"})
    net["arcs"] += [["p3", "t3"], ["t3", "p2"], ["t3", "p3"]]

    issue = next(e for e in check_document(data).errors if e.code == "unbounded")

    assert "without limit" in issue.message
    assert "repeating" in issue.message
    assert issue.witness is not None
    assert "t3" in issue.witness


def test_three_long_parallel_chains_reduce_to_a_handful_of_markings() -> None:
    paths = [" ".join(f"p{lane}{i} t{lane}{i}" for i in range(30)) for lane in range(3)]
    performers = {
        f"t{lane}{i}": ("c" if lane else "o") + str(lane) for lane in range(3) for i in range(30)
    }
    chains = [f"ps tsplit {path} pj{lane} tjoin pe" for lane, path in enumerate(paths)]
    data = document(process("N", *chains, performers=performers))

    report = check_document(data)

    assert report.sound is True
    assert report.stats["net_transitions"] == 182
    assert report.stats["markings"] <= 3  # without reduction: about 61^3 = 226 981


def test_a_state_space_past_the_cap_is_too_large_to_decide_not_a_hang() -> None:
    pattern = read_pattern(two_lanes([]))
    analysis = analyse(build_execution_net(pattern), Budget(max_markings=2))

    assert analysis.decided is False
    assert analysis.sound is None
    report = check_document(two_lanes([]), Budget(max_markings=2))
    assert [w.code for w in report.warnings if w.code == "state-space-too-large"] == [
        "state-space-too-large"
    ]
    assert "too large to decide: 2 markings" in report.warnings[-1].message


def test_the_reduction_keeps_every_original_firing_in_order() -> None:
    net = build_execution_net(read_pattern(two_lanes([("to1", "tc2", "time")])))

    reduced = reduce_net(net)

    firings = [f for t in reduced.transitions for f in t.firings]
    assert sorted(firings) == sorted(t.id for t in net.transitions)
    chain = next(t.firings for t in reduced.transitions if t.firings[0] == "start:tc2")
    assert chain[:2] == ("start:tc2", "complete:tc2")


def test_a_deadlock_without_constraints_names_what_the_join_lacks() -> None:
    # to2 skips the split: the operator's branch arrives at the join without the cobot's.
    net = process(
        "N",
        "p1 t1 p2 tc1 p3 t2 p4",
        "t1 p5 to1 p6 t2",
        "p1 to2 p5",
        performers={"tc1": "c", "to1": "o", "to2": "o"},
    )

    deadlock = next(e for e in check_document(document(net)).errors if "deadlock" in e.message)

    assert deadlock.witness == ("start to2", "complete to2", "start to1", "complete to1")
    assert deadlock.message.endswith("Split/join t2 waits for a token in place p3")
    assert deadlock.elements == ("t2",)
