"""The execution net as JSON for the token game: the engine's net, described on the pattern's elements."""

from typing import Any

from hrc.engine.document import read_pattern
from hrc.engine.execution import build_execution_net
from hrc.engine.tokengame import execution_net_json
from tests.engine.builders import example, two_lanes


def _by_id(items: list[dict[str, Any]]) -> dict[str, dict[str, Any]]:
    return {item["id"]: item for item in items}


def test_tasks_split_into_start_and_complete_around_a_busy_place() -> None:
    net = execution_net_json(read_pattern(example("synch_1o1c_assembly")))
    transitions = _by_id(net["transitions"])
    assert transitions["start:tc1"] == {
        "id": "start:tc1",
        "label": "start tc1",
        "kind": "start",
        "task": "tc1",
        "performer": "c",
        "resets": [],
    }
    assert transitions["t1"]["kind"] == "silent"
    assert transitions["t1"]["performer"] is None
    places = _by_id(net["places"])
    assert places["running:tc1"] == {
        "id": "running:tc1",
        "label": "tc1 running",
        "tokens": 0,
        "kind": "busy",
        "of": "tc1",
    }
    assert places["p1"]["tokens"] == 1
    assert places["p1"]["kind"] == "flow"
    assert {("p2", "start:tc1"), ("start:tc1", "running:tc1"), ("running:tc1", "complete:tc1")} <= {
        tuple(arc) for arc in net["arcs"]
    }
    assert (net["initial"], net["final"]) == ({"p1": 1}, {"p9": 1})


def test_a_time_constraint_is_a_place_from_one_completion_to_the_other_start() -> None:
    net = execution_net_json(read_pattern(example("synch_1o1c_assembly")))
    place = _by_id(net["places"])["time:to1>tc2"]
    assert place["kind"] == "constraint"
    assert place["of"] == ["to1", "tc2"]
    assert place["constraint"] == {"index": 0, "type": "time", "role": "time"}
    assert "to1" in place["needs"]
    arcs = {tuple(arc) for arc in net["arcs"]}
    assert {("complete:to1", "time:to1>tc2"), ("time:to1>tc2", "start:tc2")} <= arcs
    assert "time:to1>tc2" in net["ignored"]


def test_a_func_constraint_is_two_places_named_by_their_role() -> None:
    data = two_lanes([("to1", "tc2", "func")])
    places = [
        p for p in execution_net_json(read_pattern(data))["places"] if p["kind"] == "constraint"
    ]
    # The cobot's task supports the operator's.
    assert [
        (p["id"], p["constraint"]["role"], p["constraint"]["index"], p["of"]) for p in places
    ] == [
        ("func-start:tc2>to1", "func-start", 0, ["to1", "tc2"]),
        ("func-done:to1>tc2", "func-done", 0, ["to1", "tc2"]),
    ]


def test_it_describes_exactly_the_engines_net() -> None:
    pattern = read_pattern(example("coll_1o2c_assisted_handling"))
    engine_net = build_execution_net(pattern)
    net = execution_net_json(pattern)
    assert [p["id"] for p in net["places"]] == list(engine_net.places)
    assert [t["id"] for t in net["transitions"]] == [t.id for t in engine_net.transitions]
    expected = {(p, t.id) for t in engine_net.transitions for p, _ in t.pre}
    expected |= {(t.id, p) for t in engine_net.transitions for p, _ in t.post}
    assert {tuple(arc) for arc in net["arcs"]} == expected
