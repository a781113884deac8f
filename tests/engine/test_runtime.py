"""The run-time firing rule (CaseNet): settle, start, complete, guards, messages, space pairs."""

import functools
import random
from collections import Counter
from typing import Any

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from hrc.engine import read_pattern
from hrc.engine.model import Pattern
from hrc.engine.petri import Marking
from hrc.engine.runtime import (
    MAX_SILENT_FIRINGS,
    CaseNet,
    NotEnabled,
    RuntimeFault,
    SpacePair,
    apply_outputs,
    correlates,
    resolve,
)
from tests.engine.builders import EXAMPLES, document, example, process, two_lanes

Doc = dict[str, Any]
EXAMPLE_NAMES = sorted(path.stem for path in EXAMPLES.glob("*.json"))


def _configured(data: Doc, **extra: Doc) -> Doc:
    """data with keys added to transitions: `x1={"guard": "data.ok"}`."""
    for net in data["processes"]:
        for transition in net["transitions"]:
            transition.update(extra.get(transition["id"], {}))
    return data


@functools.cache
def _example_net(name: str) -> CaseNet:
    return CaseNet(read_pattern(example(name)))


# Random runs of the thesis examples, checked against pattern-format.md ----------------


def _performer_type(pattern: Pattern, task: str) -> str:
    transition = pattern.transition(task)
    assert transition is not None
    assert transition.performer is not None
    actor = pattern.actor(transition.performer)
    assert actor is not None
    return actor.type


def _func_pairs(pattern: Pattern) -> list[tuple[str, str]]:
    """(supporter, supported) of each func constraint, as pattern-format.md defines it."""
    pairs = []
    for c in pattern.constraints:
        if c.type != "func":
            continue
        kinds = [_performer_type(pattern, t) for t in (c.source, c.target)]
        supporter = c.target if kinds == ["operator", "cobot"] else c.source
        pairs.append((supporter, c.target if supporter == c.source else c.source))
    return pairs


class _Run:
    """One case driven by a seeded random scheduler, checking the constraints after every step."""

    def __init__(self, net: CaseNet, rng: random.Random) -> None:
        self.net, self.rng = net, rng
        self.pattern = net.pattern
        self.time = [(c.source, c.target) for c in self.pattern.constraints if c.type == "time"]
        self.func = _func_pairs(self.pattern)
        self.trace: list[tuple[str, str]] = []
        self.running: Counter[str] = Counter()
        self.marking, _ = net.settle(net.initial, {})

    def count(self, kind: str, task: str) -> int:
        return self.trace.count((kind, task))

    def last(self, kind: str, task: str) -> int:
        """Index of the latest such event in the trace, -1 when there is none."""
        return max((i for i, e in enumerate(self.trace) if e == (kind, task)), default=-1)

    def moves(self) -> list[tuple[str, str]]:
        starts = [("start", t) for t in self.net.startable(self.marking)]
        completions = [
            ("complete", t) for t in sorted(self.running) if self.net.can_complete(self.marking, t)
        ]
        return starts + completions

    def step(self) -> None:
        moves = self.moves()
        assert moves, f"stuck in {self.marking} after {self.trace}"
        kind, task = self.rng.choice(moves)
        if kind == "start":
            before, self.marking = self.marking, self.net.start(self.marking, task)
            self.running[task] += 1
            if task in self.net.starts_alone:
                self.check_started_alone(task, before)
        else:
            self.marking = self.net.complete(self.marking, task)
            self.running[task] -= 1
            self.running += Counter()  # drops tasks no longer running
        self.trace.append((kind, task))
        self.check_trace(kind, task)
        self.marking, _ = self.net.settle(self.marking, {})
        self.check_runtime_refuses()

    def check_started_alone(self, task: str, before: Marking) -> None:
        """A start the runtime follows with nothing (starts_alone) moved no other enabling."""
        own = (f"start:{task}", f"complete:{task}")
        for transition in self.net.net.transitions:
            if transition.id not in own:
                enabled = transition.is_enabled(before), transition.is_enabled(self.marking)
                assert enabled[0] == enabled[1], (task, transition.id, self.trace)

    def check_trace(self, kind: str, task: str) -> None:
        for a, b in self.time:
            # every start of b is preceded by its own completion of a
            assert self.count("start", b) <= self.count("complete", a), (a, b, self.trace)
        for supporter, supported in self.func:
            if (kind, task) == ("start", supported):
                assert self.running[supporter] > 0, (supporter, supported, self.trace)
            if (kind, task) == ("complete", supporter):
                assert self.running[supported] == 0, (supporter, supported, self.trace)
                assert self.last("complete", supported) > self.last("start", supporter), (
                    supporter,
                    supported,
                    self.trace,
                )

    def check_runtime_refuses(self) -> None:
        """What the constraints forbid now, the runtime neither offers nor allows."""
        startable = self.net.startable(self.marking)
        assert startable == [t for t in self.net.tasks if self.net.can_start(self.marking, t)]
        for a, b in self.time:
            if self.count("start", b) == self.count("complete", a):
                assert b not in startable
                with pytest.raises(NotEnabled, match=f"a completion of {a} "):
                    self.net.start(self.marking, b)
        for supporter, supported in self.func:
            if self.running[supporter] == 0:
                assert supported not in startable
            if self.last("complete", supported) < self.last("start", supporter):
                assert not self.net.can_complete(self.marking, supporter), self.trace
        for task in self.net.tasks:
            if self.running[task] == 0:
                assert not self.net.can_complete(self.marking, task)

    def to_the_end(self, max_steps: int = 500) -> None:
        for _ in range(max_steps):
            if self.net.is_final(self.marking):
                return
            self.step()
        pytest.fail(f"no end after {max_steps} steps: {self.trace}")


@pytest.mark.parametrize("name", EXAMPLE_NAMES)
def test_every_example_runs_to_its_end_under_a_random_scheduler(name: str) -> None:
    net = _example_net(name)
    ran: set[str] = set()
    for seed in range(20):
        run = _Run(net, random.Random(seed))
        run.to_the_end()

        assert net.is_final(run.marking)
        assert +run.running == Counter()
        ran |= {t for _, t in run.trace}
    assert ran == set(net.tasks)  # a choice's every branch is taken in some run


def test_the_examples_cover_every_constraint_type() -> None:
    types = {c.type for name in EXAMPLE_NAMES for c in _example_net(name).pattern.constraints}

    assert types == {"time", "func", "space"}


@settings(max_examples=150, deadline=None)
@given(st.sampled_from(EXAMPLE_NAMES), st.randoms(use_true_random=False))
def test_any_schedule_of_an_example_keeps_its_constraints_and_ends(
    name: str, rng: random.Random
) -> None:
    run = _Run(_example_net(name), rng)
    run.to_the_end()


def test_a_func_supporter_cannot_complete_before_the_supported_task_has() -> None:
    net = CaseNet(read_pattern(two_lanes([("to1", "tc2", "func")])))  # tc2 supports to1
    marking, _ = net.settle(net.initial, {})
    marking = net.complete(net.start(marking, "tc1"), "tc1")

    assert not net.can_start(marking, "to1")
    marking = net.start(marking, "tc2")
    assert not net.can_complete(marking, "tc2")
    marking = net.start(marking, "to1")
    assert not net.can_complete(marking, "tc2")
    with pytest.raises(NotEnabled, match=r"to1 to complete \(func constraint: tc2 supports to1\)"):
        net.complete(marking, "tc2")
    marking = net.complete(marking, "to1")
    assert net.can_complete(marking, "tc2")


def test_a_held_supporter_names_the_supported_tasks_it_still_waits_for() -> None:
    # tc2 supports to1 and to2: it holds until both have completed.
    net = CaseNet(read_pattern(two_lanes([("to1", "tc2", "func"), ("to2", "tc2", "func")])))
    marking, _ = net.settle(net.initial, {})
    marking = net.start(net.complete(net.start(marking, "tc1"), "tc1"), "tc2")
    marking = net.start(marking, "to1")

    assert net.holding_for("tc2", marking) == ["to1", "to2"]
    marking = net.complete(marking, "to1")
    assert net.holding_for("tc2", marking) == ["to2"]
    marking = net.complete(net.start(marking, "to2"), "to2")
    assert net.holding_for("tc2", marking) == []
    assert net.holding_for("tc2") == ["to1", "to2"]  # without a marking: every supported task
    assert net.holding_for("tc1") == []  # no func constraint on tc1


# Deferred choice ---------------------------------------------------------------------


def test_tasks_sharing_an_input_place_are_both_startable_until_one_starts() -> None:
    net = CaseNet(
        read_pattern(
            document(process("N", "p1 ta p2", "p1 tb p2", performers={"ta": "o", "tb": "c"}))
        )
    )

    assert net.startable(net.initial) == ["ta", "tb"]
    after = net.start(net.initial, "tb")
    assert net.startable(after) == []
    assert not net.can_start(after, "ta")
    with pytest.raises(NotEnabled, match="ta cannot start: it waits for a token in p1"):
        net.start(after, "ta")
    assert net.is_final(net.complete(after, "tb"))


def test_a_task_starts_alone_unless_another_transition_takes_from_the_places_it_touches() -> None:
    choice = CaseNet(
        read_pattern(
            document(process("N", "p1 ta p2", "p1 tb p2", performers={"ta": "o", "tb": "c"}))
        )
    )
    sequence = CaseNet(read_pattern(two_lanes([])))
    timed = CaseNet(read_pattern(two_lanes([("tc1", "to1", "time")])))  # to1 after tc1
    supported = CaseNet(read_pattern(two_lanes([("to1", "tc2", "func")])))  # tc2 supports to1

    assert choice.starts_alone == frozenset()  # each start withdraws the other
    assert sequence.starts_alone == frozenset(sequence.tasks)
    assert timed.starts_alone == frozenset(timed.tasks)  # tc1's completion lets to1 go
    assert set(supported.tasks) - supported.starts_alone == {"tc2"}  # its start lets to1 go


def test_starting_a_task_leaves_the_marking_it_was_given_alone() -> None:
    net = CaseNet(
        read_pattern(
            document(process("N", "p1 ta p2", "p1 tb p2", performers={"ta": "o", "tb": "c"}))
        )
    )
    before = net.initial

    net.start(before, "ta")

    assert before == Marking({"p1": 1})


# Guards ------------------------------------------------------------------------------


def _xor() -> CaseNet:
    data = document(
        process("N", "p1 x1 p2 ta p4", "p1 x2 p3 tb p4", performers={"ta": "o", "tb": "c"})
    )
    return CaseNet(
        read_pattern(_configured(data, x1={"guard": "data.ok"}, x2={"guard": "not data.ok"}))
    )


@pytest.mark.parametrize(("ok", "branch", "fired"), [(True, "ta", "x1"), (False, "tb", "x2")])
def test_an_xor_split_with_guards_routes_by_case_data(ok: bool, branch: str, fired: str) -> None:
    net = _xor()

    marking, firings = net.settle(net.initial, {"ok": ok})

    assert firings == [fired]
    assert net.startable(marking) == [branch]


def test_a_silent_transition_whose_guard_holds_for_no_branch_does_not_fire() -> None:
    net = CaseNet(
        read_pattern(
            _configured(
                document(process("N", "p1 x1 p2 ta p3", performers={"ta": "o"})),
                x1={"guard": "data.ok"},
            )
        )
    )

    marking, fired = net.settle(net.initial, {"ok": False})

    assert (marking, fired) == (net.initial, [])
    assert net.startable(marking) == []


def _loop(guard_back: str, guard_exit: str) -> CaseNet:
    """x0 leads into task ta; after it, xback goes round again and xexit leaves."""
    data = document(process("N", "p0 x0 p1 ta p2 xback p1", "p2 xexit p3", performers={"ta": "o"}))
    _configured(
        data,
        ta={"task": {"outputs": {"count": "data.count + 1"}}},
        xback={"guard": guard_back},
        xexit={"guard": guard_exit},
    )
    return CaseNet(read_pattern(data))


def test_a_loop_guarded_by_a_counter_runs_n_times_then_exits() -> None:
    net = _loop("data.count < 3", "data.count >= 3")
    data: dict[str, Any] = {"count": 0}
    marking, _ = net.settle(net.initial, data)
    runs = 0
    while not net.is_final(marking):
        assert net.startable(marking) == ["ta"], (runs, marking)
        marking = net.complete(net.start(marking, "ta"), "ta")
        data = apply_outputs(net.tasks["ta"], "ta", {}, data)
        runs += 1
        marking, fired = net.settle(marking, data)
        assert fired == (["xexit"] if runs == 3 else ["xback"])

    assert runs == 3
    assert data == {"count": 3}


def test_a_guard_that_fails_raises_a_runtime_fault_naming_the_transition() -> None:
    net = _xor()

    with pytest.raises(RuntimeFault, match=r"The guard of x1 failed: .*has no key 'ok'"):
        net.settle(net.initial, {"okay": True})


def test_a_silent_loop_without_exit_stops_after_max_silent_firings() -> None:
    data = document(process("N", "p0 x0 p1 xexit p2", "p1 xspin p1", performers={}))
    data["actors"] = [{"id": "o", "type": "operator"}]
    net = CaseNet(read_pattern(_configured(data, xexit={"guard": "data.done"})))

    with pytest.raises(RuntimeFault, match=f"fired {MAX_SILENT_FIRINGS} times in a row .*xspin"):
        net.settle(net.initial, {"done": False})
    assert net.settle(net.initial, {"done": True}) == (Marking({"p2": 1}), ["x0", "xexit"])


# Outputs and configuration values ---------------------------------------------------------


def test_a_task_without_outputs_stores_its_result_under_its_id() -> None:
    net = _xor()

    data = apply_outputs(net.tasks["ta"], "ta", {"detected": True}, {"ok": True})

    assert data == {"ok": True, "ta": {"detected": True}}
    assert apply_outputs(net.tasks["ta"], "ta", {}, {"ok": True}) == {"ok": True}


def test_outputs_read_the_result_and_the_data_before_the_task() -> None:
    data = document(process("N", "p1 ta p2", performers={"ta": "c"}))
    outputs = {"a": "data.b", "b": "data.a", "pose": "result.pose"}
    net = CaseNet(read_pattern(_configured(data, ta={"task": {"outputs": outputs}})))

    after = apply_outputs(net.tasks["ta"], "ta", {"pose": [1, 2]}, {"a": 1, "b": 2, "c": 3})

    assert after == {"a": 2, "b": 1, "c": 3, "pose": [1, 2]}


def test_an_output_that_fails_raises_a_runtime_fault_naming_the_task() -> None:
    net = _loop("data.count < 3", "data.count >= 3")

    with pytest.raises(RuntimeFault, match="The output 'count' of ta failed"):
        apply_outputs(net.tasks["ta"], "ta", {}, {})


def test_resolve_evaluates_expressions_and_names_the_task_when_one_fails() -> None:
    assert resolve("tc1", ["=data.x * 2", "x", 3], {"x": 4}) == [8, "x", 3]
    with pytest.raises(RuntimeFault, match="The configuration of tc1 failed"):
        resolve("tc1", "=data.y", {"x": 4})


# Messages -----------------------------------------------------------------------------


def _waiting_for_a_part() -> CaseNet:
    data = document(process("N", "p0 x0 p1 xm p2 ta p3", performers={"ta": "o"}))
    message = {"name": "part-arrived", "correlation": {"order": "data.order"}}
    return CaseNet(read_pattern(_configured(data, xm={"message": message})))


def test_a_message_transition_waits_for_its_message_and_fires_on_receive() -> None:
    net = _waiting_for_a_part()

    marking, fired = net.settle(net.initial, {"order": 7})

    assert fired == ["x0"]
    assert net.startable(marking) == []
    assert [(t, m.name) for t, m in net.waiting_messages(marking)] == [("xm", "part-arrived")]
    after = net.receive(marking, "xm")
    assert net.waiting_messages(after) == []
    assert net.startable(after) == ["ta"]


def test_no_message_is_awaited_before_the_case_reaches_it() -> None:
    net = _waiting_for_a_part()

    assert net.waiting_messages(net.initial) == []
    with pytest.raises(NotEnabled, match="the message of xm: it waits for a token in p1"):
        net.receive(net.initial, "xm")


def _customer_and_supplier() -> CaseNet:
    """A customer who may order (xo sends "order") or not (xn), and a supplier's pool that
    the order starts (xs waits for it)."""
    customer = process("C", "p0 tc p1 xo p2", "p1 xn p2", performers={"tc": "o"})
    supplier = process("S", "p5 xs p6 ts p7", performers={"ts": "s"})
    for net in (customer, supplier):
        net["completion"] = "implicit"
    order = {"name": "order", "correlation": {"case": "case.id"}}
    data = _configured(
        document(customer, supplier),
        xo={"send": {"name": "order", "correlation": {"case": "=case.id"}}},
        xs={"message": order},
        xn={"guard": "true"},
    )
    return CaseNet(read_pattern(data))


def test_a_pool_its_message_never_started_leaves_the_case_complete() -> None:
    net = _customer_and_supplier()
    marking = net.complete(net.start(net.initial, "tc"), "tc")
    marking = net.transition("xn").fire(marking)  # the customer orders nothing

    assert dict(marking) == {"p2": 1, "p5": 1}
    assert net.is_final(marking)


def test_a_process_waiting_for_a_message_from_outside_keeps_the_case_waiting() -> None:
    net = _waiting_for_a_part()  # its first step after x0: a message no process sends
    alone = document(process("N", "p1 xm p2 ta p3", performers={"ta": "o"}))
    message = {"name": "part-arrived", "correlation": {"case": "case.id"}}
    waiting = CaseNet(read_pattern(_configured(alone, xm={"message": message})))

    assert not waiting.is_final(waiting.initial)
    assert not net.is_final(net.initial)


def test_a_pool_a_message_started_must_end_before_the_case_has() -> None:
    net = _customer_and_supplier()
    marking = net.complete(net.start(net.initial, "tc"), "tc")
    marking = net.receive(net.transition("xo").fire(marking), "xs")

    assert not net.is_final(marking)
    assert net.is_final(net.complete(net.start(marking, "ts"), "ts"))
    assert not net.is_final(net.initial)  # the customer's own start is not a message's


@pytest.mark.parametrize("transition", ["x0", "start:ta", "ta"])
def test_receive_fires_only_message_transitions(transition: str) -> None:
    net = _waiting_for_a_part()

    with pytest.raises(NotEnabled, match=f"^{transition} waits for no message"):
        net.receive(net.initial, transition)


def test_a_message_correlates_only_with_equal_keys() -> None:
    net = _waiting_for_a_part()
    message = net.messages["xm"]
    data = {"order": 7}

    assert correlates(message, data, {"order": 7})
    assert not correlates(message, data, {"order": 8})
    assert not correlates(message, data, {"order": "7"})
    assert not correlates(message, data, {})
    assert not correlates(message, data, {"order": 7, "line": 2})
    assert not correlates(message, {}, {"order": 7})  # the case has no order yet
    assert not correlates(message, {"order": 1}, {"order": True})  # JSON: true is not 1


# Space pairs ----------------------------------------------------------------------------


def test_space_constraints_pair_each_operator_task_with_its_cobot_task() -> None:
    net = CaseNet(read_pattern(two_lanes([("tc1", "to1", "space"), ("to2", "tc3", "space")])))

    assert net.space_pairs == (
        SpacePair("tc1", "to1", ("cobot", "operator"), "pause"),
        SpacePair("to2", "tc3", ("operator", "cobot"), "pause"),
    )


def test_a_space_constraint_that_interrupts_slow_gives_mode_slow() -> None:
    data = two_lanes([("tc1", "to1", "space"), ("to2", "tc3", "space")], declared="cooperation")
    data["constraints"][1]["interrupt"] = "slow"

    net = CaseNet(read_pattern(data))

    assert [(p.second, p.mode) for p in net.space_pairs] == [("to1", "pause"), ("tc3", "slow")]


def test_the_polishing_example_pairs_the_operator_with_the_cobot_on_each_side() -> None:
    net = _example_net("coop_1o1c_polishing")

    assert {frozenset((p.first, p.second)) for p in net.space_pairs} == {
        frozenset(pair) for pair in (("to1", "tc1"), ("to1", "tc2"), ("to2", "tc2"), ("to2", "tc3"))
    }


def test_a_space_constraint_between_two_operators_gives_a_pair_of_operators() -> None:
    net = _example_net("coop_2o2c_quality_inspection")

    assert {(p.first, p.second, p.kinds, p.mode) for p in net.space_pairs} == {
        ("tc12", "to11", ("cobot", "operator"), "pause"),
        ("to12", "to21", ("operator", "operator"), "wait"),
        ("to22", "tc21", ("operator", "cobot"), "pause"),
    }


def test_time_and_func_constraints_give_no_space_pairs() -> None:
    assert _example_net("synch_1o1c_assembly").space_pairs == ()
    assert _example_net("coll_1o1c_collaborative_assembly").space_pairs == ()


# Why not ------------------------------------------------------------------------------


def test_why_not_names_the_time_constraint_a_start_waits_for() -> None:
    net = CaseNet(read_pattern(two_lanes([("to1", "tc2", "time")])))
    marking, _ = net.settle(net.initial, {})
    marking = net.complete(net.start(marking, "tc1"), "tc1")
    marking = net.start(marking, "to1")

    assert net.why_not(marking, "start:tc2") == "a completion of to1 (time constraint to1 → tc2)"
    with pytest.raises(NotEnabled, match="tc2 cannot start: it waits for a completion of to1"):
        net.start(marking, "tc2")
    assert net.why_not(net.complete(marking, "to1"), "start:tc2") == ""


def test_why_not_lists_every_missing_input() -> None:
    net = CaseNet(read_pattern(two_lanes([("to1", "tc2", "time")])))
    marking, _ = net.settle(net.initial, {})

    assert net.why_not(marking, "start:tc2") == (
        "a token in p3; a completion of to1 (time constraint to1 → tc2)"
    )


def test_an_unknown_task_cannot_start() -> None:
    net = CaseNet(read_pattern(two_lanes([])))

    with pytest.raises(NotEnabled, match="tc9 cannot start: the pattern has no start:tc9"):
        net.start(net.initial, "tc9")
