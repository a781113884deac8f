"""The `send` key: a task or silent transition sends a message; `case` in message expressions."""

from typing import Any

import pytest

from hrc.engine import read_pattern
from hrc.engine.runtime import CaseNet, RuntimeFault, correlates, outgoing
from hrc.engine.taskconfig import ConfigError, config_issues, message_of, send_of
from tests.engine.test_taskconfig import _doc, _silent

SYNC = {
    "name": "sync1",
    "correlation": {"case": "=case.id", "order": "=data.order"},
    "payload": {
        "part": "=data.part",
        "ready": True,
        "poses": ["=data.pose", [1, "=case.reference"]],
    },
}


def test_a_send_has_a_name_correlation_and_payload_of_literals_and_expressions() -> None:
    send = send_of(_silent(send=SYNC))

    assert send is not None
    assert send.name == "sync1"
    assert dict(send.correlation) == SYNC["correlation"]
    assert dict(send.payload) == SYNC["payload"]


def test_a_send_needs_only_a_name() -> None:
    send = send_of(_silent(send={"name": "done"}))

    assert send is not None
    assert (send.name, dict(send.correlation), dict(send.payload)) == ("done", {}, {})
    assert send_of(_silent()) is None


def test_a_task_and_a_silent_transition_may_both_send() -> None:
    data = _doc(tc1={"send": SYNC}, to1={"send": {"name": "checked"}}, x1={"send": SYNC})

    assert config_issues(read_pattern(data)) == []
    assert set(CaseNet(read_pattern(data)).sends) == {"tc1", "to1", "x1"}


def test_a_message_transition_may_send_as_it_fires() -> None:
    data = _doc(x1={"message": {"name": "go", "correlation": {"c": "case.id"}}, "send": SYNC})

    assert config_issues(read_pattern(data)) == []


@pytest.mark.parametrize(
    ("send", "complaint"),
    [
        ("sync1", "'send' must be an object with a 'name'"),
        ({"correlation": {}}, "'send' needs a 'name'"),
        ({"name": "  "}, "'send' needs a 'name'"),
        ({"name": 7}, "'send' needs a 'name'"),
        ({"name": "m", "to": "p2"}, "'send' has no key 'to'"),
        ({"name": "m", "correlation": ["case"]}, "the 'send' 'correlation' must map keys"),
        ({"name": "m", "payload": "=data"}, "the 'send' 'payload' must map keys"),
        (
            {"name": "m", "correlation": {"k": "=result.x"}},
            "send correlation 'k': unknown name 'result'",
        ),
        ({"name": "m", "payload": {"k": ["=data.a +"]}}, "send payload 'k':"),
        ({"name": "m", "payload": {"k": {"deep": "=item.x"}}}, "unknown name 'item'"),
    ],
)
def test_a_malformed_send_is_refused_naming_the_key(send: object, complaint: str) -> None:
    with pytest.raises(ConfigError, match=r"^x1: ") as caught:
        send_of(_silent(send=send))

    assert complaint in str(caught.value)


@pytest.mark.parametrize("where", ["tc1", "to1", "x1"])
def test_the_check_refuses_a_bad_send_as_a_task_config_error_naming_the_transition(
    where: str,
) -> None:
    issues = config_issues(read_pattern(_doc(**{where: {"send": {"name": "m", "nope": 1}}})))

    assert [(i.code, i.elements) for i in issues] == [("task-config", (where,))]
    assert f"{where}: 'send' has no key 'nope'" in issues[0].message


def test_a_receiving_correlation_may_read_the_case() -> None:
    message = message_of(_silent(message={"name": "m", "correlation": {"c": "case.id"}}))
    assert message is not None

    assert correlates(message, {}, {"c": 12}, {"id": 12, "reference": "R"})
    assert not correlates(message, {}, {"c": 13}, {"id": 12, "reference": "R"})
    assert not correlates(message, {}, {"c": 12})  # no case given: nothing to read


def test_a_receiving_correlation_may_not_read_the_result() -> None:
    with pytest.raises(ConfigError, match="unknown name 'result'"):
        message_of(_silent(message={"name": "m", "correlation": {"c": "result.id"}}))


def test_outgoing_evaluates_the_send_over_the_data_and_the_case() -> None:
    send = send_of(_silent(send=SYNC))
    assert send is not None
    data: dict[str, Any] = {"order": "A-1", "part": {"id": 3}, "pose": [0, 1]}

    message = outgoing("x1", send, data, {"id": 5, "reference": "R-5"})

    assert message.name == "sync1"
    assert message.correlation == {"case": 5, "order": "A-1"}
    assert message.payload == {"part": {"id": 3}, "ready": True, "poses": [[0, 1], [1, "R-5"]]}


def test_outgoing_that_fails_on_the_data_names_the_message_and_transition() -> None:
    send = send_of(_silent(send=SYNC))
    assert send is not None

    with pytest.raises(RuntimeFault, match=r"The message 'sync1' that x1 sends failed"):
        outgoing("x1", send, {}, {"id": 5, "reference": ""})
