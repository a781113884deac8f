"""A document predicted with what the plant measured: how often each choice's branch was taken
weighs the choice, where the earlier versions had every branch."""

from typing import Any

from hrc.patterns.prediction import Measured, Options, predict_document


def _rush_or_calm() -> dict[str, Any]:
    """A choice by the case data: `rush` leads to the operator's task fast, `calm` to slow; the
    data say calm."""
    return {
        "format": "hrc-pattern/1",
        "name": "Rush or calm",
        "actors": [{"id": "o", "type": "operator"}],
        "data": {"rush": False},
        "processes": [
            {
                "id": "N",
                "workpiece": "w",
                "actors": ["o"],
                "places": [{"id": "p1", "tokens": 1}] + [{"id": f"p{n}"} for n in (2, 3, 4)],
                "transitions": [
                    {"id": "rush", "guard": "data.rush"},
                    {"id": "calm", "guard": "not data.rush"},
                    {"id": "fast", "performer": "o", "label": "fast"},
                    {"id": "slow", "performer": "o", "label": "slow"},
                ],
                "arcs": [
                    ["p1", "rush"],
                    ["rush", "p2"],
                    ["p2", "fast"],
                    ["fast", "p4"],
                    ["p1", "calm"],
                    ["calm", "p3"],
                    ["p3", "slow"],
                    ["slow", "p4"],
                ],
            }
        ],
        "constraints": [],
    }


def _runs(measured: Measured | None, **options: Any) -> dict[str, int]:
    prediction = predict_document(
        _rush_or_calm(), Options(cases=400, **options), measured
    ).prediction
    return {load.task: load.runs for load in prediction.tasks}


def test_the_branches_are_taken_as_often_as_the_earlier_versions_took_them() -> None:
    measured = Measured(fired={"rush": 10, "calm": 30}, transitions=frozenset({"rush", "calm"}))

    runs = _runs(measured)

    assert runs["fast"] + runs["slow"] == 400
    assert 70 <= runs["fast"] <= 130  # a quarter of 400, drawn with the fixed seed


def test_without_every_branch_measured_the_guards_choose() -> None:
    # The earlier versions had no "rush": how often "calm" was taken says nothing of a choice.
    calm_only = Measured(fired={"calm": 30}, transitions=frozenset({"calm"}))

    assert "fast" not in _runs(calm_only)
    assert "fast" not in _runs(None)


def test_the_engineers_weights_come_before_the_measured_ones() -> None:
    measured = Measured(fired={"rush": 10, "calm": 30}, transitions=frozenset({"rush", "calm"}))

    runs = _runs(measured, weights={"rush": 1, "calm": 0})

    assert runs == {"fast": 400}
