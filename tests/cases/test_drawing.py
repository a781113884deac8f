"""The net drawing of the supervisor pages: the document's layout keys when it has them."""

import copy
import math
from typing import Any

import pytest

from hrc.cases.drawing import LINE_CHARACTERS, PLACE_RADIUS, TASK_SIZE, draw_net
from hrc.engine.document import read_pattern
from hrc.engine.layout import lay_out
from tests import factories


def _laid_out() -> dict[str, Any]:
    """The hand-over document with layout keys as the editor writes them: two lanes."""
    document = factories.valid_document()
    process = document["processes"][0]
    at = {"p1": (60, 150), "to1": (200, 150), "p2": (340, 100), "tc1": (480, 50), "p3": (620, 50)}
    for element in (*process["places"], *process["transitions"]):
        x, y = at[element["id"]]
        element["layout"] = {"x": x, "y": y}
    document["layout"] = {
        "lanes": [{"actor": "c", "y": 0, "height": 100}, {"actor": "o", "y": 100, "height": 100}],
        "width": 900,
        "height": 200,
    }
    return document


def test_the_layout_keys_place_every_node_and_lane() -> None:
    drawing = draw_net(read_pattern(_laid_out()))

    assert {(n.id, n.x, n.y) for n in drawing.places} == {
        ("p1", 60, 150),
        ("p2", 340, 100),
        ("p3", 620, 50),
    }
    assert {(n.id, n.kind, n.actor, n.label) for n in drawing.transitions} == {
        ("to1", "task", "o", "prepare workpiece"),
        ("tc1", "task", "c", "place insert"),
    }
    assert [(lane.actor, lane.y, lane.height) for lane in drawing.lanes] == [
        ("c", 0, 100),
        ("o", 100, 100),
    ]
    assert drawing.width == 900  # the written size, where it holds every node
    assert drawing.height == 150 + TASK_SIZE[1] / 2 + 30  # grown to hold to1 and a margin


def test_an_arc_runs_from_rim_to_rim() -> None:
    drawing = draw_net(read_pattern(_laid_out()))
    arc = next(a for a in drawing.arcs if (a.source, a.target) == ("p1", "to1"))
    assert (arc.x1, arc.y1) == (60 + PLACE_RADIUS, 150)
    assert (arc.x2, arc.y2) == (200 - TASK_SIZE[0] / 2, 150)
    slanted = next(a for a in drawing.arcs if (a.source, a.target) == ("to1", "p2"))
    assert math.hypot(slanted.x2 - 340, slanted.y2 - 100) == pytest.approx(PLACE_RADIUS)
    assert slanted.x1 == pytest.approx(200 + TASK_SIZE[0] / 2)  # leaves through the right side


def test_a_constraint_carries_the_places_its_tokens_are_counted_in() -> None:
    drawing = draw_net(read_pattern(_laid_out()))
    [line] = drawing.constraints
    assert (line.source, line.target, line.type, line.places) == (
        "to1",
        "tc1",
        "time",
        ("time:to1>tc1",),
    )
    assert line.path.startswith("M ")


def test_a_func_constraint_has_both_of_its_places() -> None:
    document = _laid_out()
    document["constraints"] = [{"from": "to1", "to": "tc1", "type": "func"}]
    [line] = draw_net(read_pattern(document)).constraints
    assert sorted(line.places) == ["func-done:to1>tc1", "func-start:tc1>to1"]


def test_a_document_without_layout_is_laid_out_by_the_engine_in_actor_lanes() -> None:
    document = _laid_out()
    del document["processes"][0]["places"][1]["layout"]  # one node without: none is trusted
    drawing = draw_net(read_pattern(document))

    engine = lay_out(factories.valid_document())
    expected = {
        element["id"]: (element["layout"]["x"], element["layout"]["y"])
        for element in (*engine["processes"][0]["places"], *engine["processes"][0]["transitions"])
    }
    assert {n.id: (n.x, n.y) for n in (*drawing.places, *drawing.transitions)} == expected
    lanes = {lane.actor: lane for lane in drawing.lanes}
    assert sorted(lanes) == ["c", "o"]
    for task in drawing.transitions:
        lane = lanes[task.actor]
        assert lane.y <= task.y <= lane.y + lane.height, task.id
    assert drawing.width >= max(n.x for n in drawing.places) + PLACE_RADIUS


@pytest.mark.parametrize("bad", [{"x": "10", "y": 5}, {"x": True, "y": 5}, {"y": 5}, None, [1, 2]])
def test_a_layout_key_that_is_not_two_numbers_is_not_trusted(bad: Any) -> None:
    document = _laid_out()
    document["processes"][0]["transitions"][0]["layout"] = copy.deepcopy(bad)
    drawing = draw_net(read_pattern(document))
    assert next(n for n in drawing.places if n.id == "p1").x != 60  # the engine's layout


def test_an_unknown_actor_lane_is_drawn_without_a_name() -> None:
    document = _laid_out()
    document["layout"]["lanes"].append({"actor": None, "y": 200, "height": 50})
    assert draw_net(read_pattern(document)).lanes[-1].actor == ""


def test_a_label_is_cut_into_two_lines_that_fit_a_task() -> None:
    document = _laid_out()
    document["processes"][0]["transitions"][0]["label"] = (
        "check and fine-polish the first polished line"
    )
    [to1] = [n for n in draw_net(read_pattern(document)).transitions if n.id == "to1"]
    assert to1.label_lines == ["check and", "fine-polish th…"]
    assert all(len(line) <= LINE_CHARACTERS for line in to1.label_lines)
