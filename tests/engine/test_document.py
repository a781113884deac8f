"""Reading and writing `hrc-pattern/1`: shapes, messages, and keys kept through a round trip."""

import json
from typing import Any

import pytest

from hrc.engine import FormatError, check_document, read_pattern, write_pattern
from hrc.engine.document import dumps, loads, parse_json
from tests.engine.builders import example, two_lanes


def test_a_round_trip_keeps_keys_the_format_does_not_know() -> None:
    data = two_lanes([("to1", "tc2", "time")])
    data["layout"] = {"zoom": 1.5}
    data["actors"][0]["color"] = "#f00"
    data["processes"][0]["lane"] = {"y": 10}
    data["processes"][0]["places"][0]["x"] = 40
    data["processes"][0]["transitions"][2]["config"] = {"program": "pick.urp", "step": 3}
    data["constraints"][0]["note"] = "insert is placed on the prepared workpiece"

    written = write_pattern(read_pattern(data))

    assert written == data
    assert written["processes"][0]["transitions"][2]["config"] == {"program": "pick.urp", "step": 3}


def test_the_shipped_examples_are_written_back_byte_for_byte() -> None:
    data = example("coll_1o1c_collaborative_assembly")

    assert json.loads(dumps(loads(json.dumps(data)))) == data


@pytest.mark.parametrize(
    ("text", "fragment"),
    [
        ("{not json", "not JSON: Expecting property name"),
        (b'{"name": "\xc3\x28"}', "not UTF-8"),
        ("[]", "must be a JSON object, got a list"),
        ('{"format": "bpmn"}', '"format": "hrc-pattern/1", got "bpmn"'),
        ('{"format": "hrc-pattern/1", "processes": []}', "no process"),
        ('{"format": "hrc-pattern/1", "processes": {}}', "processes must be a list"),
    ],
)
def test_unreadable_documents_say_what_is_wrong(text: str | bytes, fragment: str) -> None:
    with pytest.raises(FormatError) as caught:
        loads(text)

    assert fragment in str(caught.value)
    assert all(issue.code == "format" for issue in caught.value.issues)


def _shape(change: dict[str, Any]) -> list[str]:
    data = two_lanes([])
    for path, value in change.items():
        target: Any = data
        *parents, last = path.split(".")
        for key in parents:
            target = target[int(key)] if key.isdigit() else target[key]
        target[int(last) if last.isdigit() else last] = value
    report = check_document(data)
    assert report.valid is False
    assert report.sound is None
    return [issue.message for issue in report.errors]


@pytest.mark.parametrize(
    ("change", "fragment"),
    [
        ({"actors.0.type": "robot"}, 'actors[0].type must be "cobot" or "operator", got "robot"'),
        ({"actors.0.id": 7}, "actors[0].id must be a non-empty string, got the number 7"),
        (
            {"processes.0.places.0.tokens": -1},
            "processes[0].places[0].tokens must be a whole number ≥ 0",
        ),
        ({"processes.0.places.0.tokens": True}, "tokens must be a whole number ≥ 0, got true"),
        ({"processes.0.arcs.0": ["p1"]}, "processes[0].arcs[0] must be a pair of node ids"),
        ({"processes.0.transitions.0.performer": 3}, "performer must be a string"),
        ({"constraints": [{"from": "tc1"}]}, "constraints[0].to must be a non-empty string"),
        ({"declared_pattern": "teamwork"}, "declared_pattern 'teamwork' is not one of"),
        ({"name": ["x"]}, "name must be a string"),
    ],
)
def test_wrong_shapes_are_format_errors_that_name_the_place(
    change: dict[str, Any], fragment: str
) -> None:
    messages = _shape(change)

    assert any(fragment in message for message in messages), messages


def test_every_shape_problem_is_listed_not_just_the_first() -> None:
    messages = _shape({"actors.0.type": "robot", "processes.0.arcs.1": "p2"})

    assert len(messages) == 2


def test_a_place_without_tokens_anywhere_starts_with_one_in_the_source() -> None:
    pattern = read_pattern(two_lanes([]))

    assert pattern.processes[0].initial_marking() == {"p1": 1}


def test_written_tokens_replace_the_default_marking() -> None:
    data = two_lanes([])
    data["processes"][0]["places"][0]["tokens"] = 2

    assert read_pattern(data).processes[0].initial_marking() == {"p1": 2}


def test_parse_json_reports_line_and_column() -> None:
    with pytest.raises(FormatError, match="line 2, column 1"):
        parse_json('{"a": 1,\n}')
