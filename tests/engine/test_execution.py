"""The execution net and the firing rule the runtime uses."""

from hrc.engine import read_pattern
from hrc.engine.execution import build_execution_net, possible_firings
from hrc.engine.petri import Marking, Net
from tests.engine.builders import example, two_lanes


def _net(constraints: list[tuple[str, str, str]]) -> Net:
    return build_execution_net(read_pattern(two_lanes(constraints)))


def _labels(net: Net, marking: Marking) -> list[str]:
    return [f.transition.label for f in possible_firings(net, marking)]


def _run(net: Net, *labels: str) -> Marking:
    marking = net.initial
    for label in labels:
        firing = next(f for f in possible_firings(net, marking) if f.transition.label == label)
        marking = firing.marking
    return marking


def test_each_task_is_split_into_start_and_complete() -> None:
    net = _net([])

    assert {t.label for t in net.transitions} >= {"start tc1", "complete tc1", "t1", "t2"}
    assert _labels(net, _run(net, "t1")) == ["start tc1", "start to1"]
    assert _labels(net, _run(net, "t1", "start tc1")) == ["complete tc1", "start to1"]


def test_a_time_constraint_holds_the_start_until_the_other_task_completed() -> None:
    net = _net([("to1", "tc2", "time")])
    marking = _run(net, "t1", "start tc1", "complete tc1", "start to1")

    assert "start tc2" not in _labels(net, marking)
    assert "start tc2" in _labels(
        net, _run(net, "t1", "start tc1", "complete tc1", "start to1", "complete to1")
    )


def test_a_func_constraint_starts_the_supported_task_only_while_the_cobot_supports() -> None:
    net = _net([("to1", "tc2", "func")])  # tc2 is the cobot's, so it supports to1
    before = _run(net, "t1")
    during = _run(net, "t1", "start tc1", "complete tc1", "start tc2")

    assert "start to1" not in _labels(net, before)
    assert "start to1" in _labels(net, during)
    assert "complete tc2" not in _labels(net, during)
    after = _run(net, "t1", "start tc1", "complete tc1", "start tc2", "start to1", "complete to1")
    assert "complete tc2" in _labels(net, after)


def test_a_space_constraint_adds_no_order() -> None:
    free = _net([])
    spaced = _net([("tc1", "to1", "space")])

    assert _labels(spaced, _run(spaced, "t1")) == _labels(free, _run(free, "t1"))
    assert spaced.ignored == frozenset()


def test_constraint_places_are_set_aside_for_proper_completion() -> None:
    net = _net([("to1", "tc2", "time")])

    assert net.ignored == {"time:to1>tc2"}
    assert net.final == {"p9": 1}


def test_a_firing_gives_a_new_marking_and_leaves_the_old_one_alone() -> None:
    net = _net([])
    firing = possible_firings(net, net.initial)[0]

    assert firing.marking == {"p2": 1, "p6": 1}
    assert net.initial == {"p1": 1}


def test_coexistence_starts_every_process_at_once() -> None:
    net = build_execution_net(read_pattern(example("coex_1o1c_pick_and_place")))

    assert net.initial == {"p11": 1, "p21": 1}
    assert net.final == {"p13": 1, "p23": 1}
    assert _labels(net, net.initial) == ["start t11", "start t21"]
