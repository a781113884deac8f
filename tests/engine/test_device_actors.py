"""Device actors (an actor of type cobot with a "device" key): their lane runs device calls of
their kind only, and a cobot's lane says which kinds of device it calls."""

from typing import Any

import pytest

from hrc.engine import check_document, read_pattern
from hrc.engine.taskconfig import DEVICE_CALLS, DEVICE_KINDS, device_kinds_called, task_config
from tests.engine.builders import document, process

Doc = dict[str, Any]


def _doc(axis_task: object, device: object = "linear-axis") -> Doc:
    """An axis lane (task ta1) beside a cobot lane (tc1, a display call)."""
    data = document(
        process("N", "p1 ta1 p2 tc1 p3", performers={"ta1": "axis", "tc1": "c"}),
        actors={"axis": "cobot", "c": "cobot"},
    )
    [axis] = [actor for actor in data["actors"] if actor["id"] == "axis"]
    axis["device"] = device
    for transition in data["processes"][0]["transitions"]:
        if transition["id"] == "ta1":
            transition["task"] = axis_task
        if transition["id"] == "tc1":
            transition["task"] = {"device": {"call": "display.show", "args": {"text": "hi"}}}
    return data


def _task_config_errors(data: Doc) -> list[str]:
    report = check_document(data)
    return [issue.message for issue in report.errors if issue.code == "task-config"]


MOVE = {"device": {"call": "linear-axis.move", "args": {"direction": "left", "duration_ms": 5}}}


def test_the_kinds_are_the_calls_prefixes() -> None:
    assert set(DEVICE_KINDS) == {call.split(".")[0] for call in DEVICE_CALLS}
    assert "linear-axis" in DEVICE_KINDS


def test_a_device_actors_call_of_its_kind_is_a_device_task() -> None:
    data = _doc(MOVE)
    assert _task_config_errors(data) == []
    pattern = read_pattern(data)
    transition = pattern.transition("ta1")
    assert transition is not None
    config = task_config(pattern, transition)
    assert config.kind == "device"
    assert config.device is not None
    assert config.device.call == "linear-axis.move"
    # The cobot's lane calls a display; the axis lane is its device's own.
    assert device_kinds_called(pattern) == {"c": {"display"}}


@pytest.mark.parametrize(
    ("task", "says"),
    [
        ({"step": {"program": "P", "number": 1}}, "runs device calls only"),
        ({}, "runs device calls only"),
        ({"device": {"call": "display.show", "args": {"text": "x"}}}, "cannot run display.show"),
    ],
)
def test_a_device_actors_lane_refuses_anything_but_a_call_of_its_kind(
    task: object, says: str
) -> None:
    errors = _task_config_errors(_doc(task))
    assert len(errors) == 1
    assert says in errors[0]
    assert "axis" in errors[0]


def test_an_unknown_device_kind_is_a_task_config_error_naming_the_kinds() -> None:
    errors = _task_config_errors(_doc(MOVE, device="teleporter"))
    assert any("'teleporter'" in error and "linear-axis" in error for error in errors)


def test_a_space_constraint_on_a_device_call_is_refused_for_a_time_constraint() -> None:
    data = _doc(MOVE)
    data["constraints"] = [{"from": "tc1", "to": "ta1", "type": "space"}]

    report = check_document(data)
    [issue] = [i for i in report.errors if i.code == "task-config"]

    assert set(issue.elements) == {"tc1", "ta1"}
    assert "device actor 'axis'" in issue.message
    assert "time constraint" in issue.message
    # Ordered by time instead, the same two tasks check clean.
    data["constraints"] = [{"from": "tc1", "to": "ta1", "type": "time"}]
    assert _task_config_errors(data) == []
