"""Task configuration, guards and messages: what a transition's `task`, `guard`, `message` keys may say."""

from typing import Any

import pytest

from hrc.engine import check_document, read_pattern
from hrc.engine.runtime import CaseNet, resolve
from hrc.engine.taskconfig import (
    DEFAULT_RETRIES,
    DEFAULT_TIMEOUT,
    DEVICE_CALLS,
    ConfigError,
    TaskConfig,
    config_issues,
    guard_of,
    initial_data,
    message_of,
    task_config,
)
from tests.engine.builders import document, process, two_lanes

Doc = dict[str, Any]

PROGRAM = "Coexistence_PickAndPlace"


def _doc(**extra: Any) -> Doc:
    """A cobot task tc1, an operator task to1, and a silent transition x1 between them.

    `extra` maps a transition id to the keys to add to it, e.g. `tc1={"task": {...}}`.
    The cobot actor c runs PROGRAM.
    """
    data = document(
        process("N", "p1 tc1 p2 x1 p3 to1 p4", performers={"tc1": "c", "to1": "o"}),
    )
    [cobot] = [actor for actor in data["actors"] if actor["id"] == "c"]
    cobot["program"] = PROGRAM
    for transition in data["processes"][0]["transitions"]:
        transition.update(extra.get(transition["id"], {}))
    return data


def _config(task_id: str, data: Doc) -> TaskConfig:
    pattern = read_pattern(data)
    transition = pattern.transition(task_id)
    assert transition is not None
    return task_config(pattern, transition)


def _cobot(task: object) -> TaskConfig:
    return _config("tc1", _doc(tc1={"task": task}))


def _operator(task: object) -> TaskConfig:
    return _config("to1", _doc(to1={"task": task}))


def _refused(task: object, task_id: str = "tc1") -> str:
    """The ConfigError message for a task configuration; fails when it is accepted."""
    with pytest.raises(ConfigError) as caught:
        _config(task_id, _doc(**{task_id: {"task": task}}))
    assert caught.value.transition == task_id
    assert str(caught.value).startswith(f"{task_id}: ")
    return str(caught.value)


# Defaults -------------------------------------------------------------------------


def test_a_cobot_task_without_config_runs_step_1_of_its_actors_program_with_defaults() -> None:
    config = _config("tc1", _doc())

    assert config.kind == "step"
    assert config.step is not None
    assert (config.step.program, config.step.number, config.step.workspace) == (PROGRAM, 1, 0)
    assert list(config.step.poses) == []
    assert (config.timeout, config.retries, config.outputs) == (
        DEFAULT_TIMEOUT,
        DEFAULT_RETRIES,
        None,
    )


@pytest.mark.parametrize("task", [None, {"step": {"number": 2}}])
def test_a_cobot_task_that_names_no_program_is_refused_when_checked(task: object) -> None:
    data = _doc(tc1={"task": task} if task is not None else {})
    for actor in data["actors"]:
        actor.pop("program", None)

    issues = [i for i in check_document(data).errors if i.code == "task-config"]

    assert [i.elements for i in issues] == [("tc1",)]
    assert issues[0].message.startswith("Task tc1: the cobot task names no program")
    assert "'c'" in issues[0].message


def test_a_cobot_task_without_config_runs_step_1_of_its_actors_program() -> None:
    data = _doc()
    data["actors"][0]["program"] = "Synchronized_Assembly"
    assert data["actors"][0]["id"] == "c"

    config = _config("tc1", data)

    assert config.step is not None
    assert (config.step.program, config.step.number) == ("Synchronized_Assembly", 1)


def test_a_step_without_program_takes_its_actors_program() -> None:
    data = _doc(tc1={"task": {"step": {"number": 4}}})
    data["actors"][0]["program"] = "Synchronized_Assembly"

    config = _config("tc1", data)

    assert config.step is not None
    assert (config.step.program, config.step.number) == ("Synchronized_Assembly", 4)


def test_an_actors_program_that_is_no_name_is_refused_at_its_tasks() -> None:
    data = _doc()
    data["actors"][0]["program"] = 7

    with pytest.raises(ConfigError, match=r"^tc1: the step's 'program'"):
        _config("tc1", data)


def test_an_operator_task_without_config_is_an_operator_task_with_defaults() -> None:
    config = _config("to1", _doc())

    assert config == TaskConfig("operator")
    assert config.step is None
    assert config.device is None


# Steps ------------------------------------------------------------------------------


def test_a_step_takes_literal_and_expression_values_and_resolves_them_over_case_data() -> None:
    step = {
        "program": "Cooperation_Polishing",
        "number": 2,
        "workspace": "=data.workspace",
        "poses": [[0.1, 0.2, 0.3, 0, 0, 0], "=data.part.pose"],
    }
    config = _cobot({"step": step})

    assert config.step is not None
    assert config.step.program == "Cooperation_Polishing"
    assert config.step.number == 2
    data = {"workspace": 3, "part": {"pose": [1, 2, 3, 4, 5, 6]}}
    assert resolve("tc1", config.step.workspace, data) == 3
    assert resolve("tc1", config.step.poses, data) == [
        [0.1, 0.2, 0.3, 0, 0, 0],
        [1, 2, 3, 4, 5, 6],
    ]


def test_a_pose_may_mix_numbers_and_expressions() -> None:
    config = _cobot({"step": {"poses": [[1, 2, "=data.z", 0, 0, 0]]}})

    assert config.step is not None
    assert resolve("tc1", config.step.poses, {"z": 0.5}) == [[1, 2, 0.5, 0, 0, 0]]


def test_all_the_poses_may_come_from_one_expression() -> None:
    config = _cobot({"step": {"poses": "=data.poses"}})

    assert config.step is not None
    assert config.step.poses == "=data.poses"


@pytest.mark.parametrize(
    ("step", "complaint"),
    [
        ({"number": "2"}, "'number' must be a whole number ≥ 0 or an expression"),
        ({"number": True}, "'number' must be a whole number ≥ 0 or an expression"),
        ({"number": 1.5}, "'number' must be a whole number ≥ 0 or an expression"),
        ({"workspace": None}, "'workspace' must be a whole number ≥ 0 or an expression"),
        ({"program": ""}, "'program' must be a program name"),
        ({"program": 3}, "'program' must be a program name"),
        ({"poses": [[0] * 6] * 3}, "at most 2 poses"),
        ({"poses": {"x": 1}}, "at most 2 poses"),
        ({"poses": [[0, 0, 0]]}, "each pose is a list of 6 numbers"),
        ({"poses": [[0, 0, 0, 0, 0, True]]}, "pose values are numbers, not True"),
        ({"poses": [[0, 0, 0, 0, 0, "5"]]}, "pose values are numbers, not '5'"),
    ],
)
def test_a_malformed_step_is_refused_saying_what_is_wrong(step: Doc, complaint: str) -> None:
    assert complaint in _refused({"step": step})


def test_a_step_that_is_not_an_object_is_refused() -> None:
    assert "'step' must be an object" in _refused({"step": [1]})


@pytest.mark.parametrize(
    ("step", "complaint"),
    [
        ({"number": "=result.step"}, "step number: unknown name 'result'"),
        ({"workspace": "=data.ws +"}, "step workspace:"),
        ({"poses": "=poses"}, "step poses: unknown name 'poses'"),
        ({"poses": ["=result.pose"]}, "a pose: unknown name 'result'"),
        ({"poses": [[0, 0, "=z", 0, 0, 0]]}, "a pose value: unknown name 'z'"),
    ],
)
def test_a_step_expression_may_only_read_case_data(step: Doc, complaint: str) -> None:
    assert complaint in _refused({"step": step})


# Device calls -------------------------------------------------------------------------


@pytest.mark.parametrize("call", sorted(DEVICE_CALLS))
def test_each_device_call_is_accepted_with_exactly_its_arguments(call: str) -> None:
    method, argument_names, output_names = DEVICE_CALLS[call]
    args = {name: f"=data.{name}" for name in argument_names}

    config = _cobot({"device": {"call": call, "args": args}})

    assert config.kind == "device"
    assert config.step is None
    assert config.device is not None
    assert config.device.method == method
    assert config.device.argument_names == argument_names
    assert config.device.output_names == output_names
    assert dict(config.device.args) == args


@pytest.mark.parametrize(
    ("call", "args", "named"),
    [
        ("linear-axis.move", {"direction": 1}, "direction, duration_ms"),
        (
            "linear-axis.move",
            {"direction": 1, "duration_ms": 5, "speed": 2},
            "direction, duration_ms",
        ),
        ("inspection.inspect", {}, "spot"),
        ("part-detection.scan", {"spot": 1}, "none"),
        ("display.show", ["hello"], "text"),
    ],
)
def test_a_device_call_with_wrong_arguments_names_the_ones_it_takes(
    call: str, args: object, named: str
) -> None:
    message = _refused({"device": {"call": call, "args": args}})

    assert f"the device call {call} takes the arguments: {named}." in message


def test_a_device_call_without_arguments_may_leave_out_args() -> None:
    config = _cobot({"device": {"call": "part-detection.scan"}})

    assert config.device is not None
    assert dict(config.device.args) == {}


@pytest.mark.parametrize("call", ["gripper.open", None, ["display.show"], {"x": 1}, 3])
def test_an_unknown_device_call_is_refused_listing_the_calls(call: object) -> None:
    message = _refused({"device": {"call": call, "args": {}}})

    assert all(name in message for name in DEVICE_CALLS)


def test_a_device_argument_expression_may_only_read_case_data() -> None:
    message = _refused({"device": {"call": "display.show", "args": {"text": "=result.text"}}})

    assert "argument 'text': unknown name 'result'" in message


def test_a_cobot_task_runs_a_step_or_a_device_call_not_both() -> None:
    task = {"step": {"number": 2}, "device": {"call": "part-detection.scan"}}

    assert "either a 'step' or a 'device' call, not both" in _refused(task)


@pytest.mark.parametrize("key", ["step", "device"])
def test_an_operator_task_has_no_step_or_device(key: str) -> None:
    assert f"an operator task has no '{key}'" in _refused({key: {}}, "to1")


# Operator forms, outputs, timeout, retries --------------------------------------------


def test_an_operator_form_is_a_json_schema_object() -> None:
    form = {"type": "object", "properties": {"ok": {"type": "boolean"}}, "required": ["ok"]}

    config = _operator({"instructions": "Check the seam.", "form": form})

    assert config.kind == "operator"
    assert config.form == form
    assert config.instructions == "Check the seam."


@pytest.mark.parametrize("form", [{"type": "string"}, {"properties": {}}, ["ok"], "object"])
def test_an_operator_form_that_is_no_json_schema_object_is_refused(form: object) -> None:
    assert "'form' must be a JSON Schema object" in _refused({"form": form}, "to1")


def test_instructions_are_text() -> None:
    assert "'instructions' must be text" in _refused({"instructions": ["do it"]}, "to1")


def test_outputs_may_read_the_result_and_the_case_data() -> None:
    outputs = {"count": "data.count + 1", "seen": "result.detected"}

    assert _cobot({"outputs": outputs}).outputs == outputs


@pytest.mark.parametrize(
    ("outputs", "complaint"),
    [
        ({"x": "case.x"}, "output 'x': unknown name 'case'"),
        ({"x": "result."}, "output 'x':"),
        ({"x": 1}, "'outputs' must map case data keys to expressions"),
        (["x"], "'outputs' must map case data keys to expressions"),
    ],
)
def test_malformed_outputs_are_refused(outputs: object, complaint: str) -> None:
    assert complaint in _refused({"outputs": outputs})


@pytest.mark.parametrize("timeout", [0.5, 1, 86_400])
def test_a_timeout_between_0_and_a_day_is_taken(timeout: float) -> None:
    assert _cobot({"timeout": timeout}).timeout == timeout


@pytest.mark.parametrize("timeout", [0, -1, 86_401, True, "10", None])
def test_a_timeout_outside_0_to_a_day_is_refused(timeout: object) -> None:
    assert "'timeout' must be a number of seconds between 0 and 86400" in _refused(
        {"timeout": timeout}
    )


@pytest.mark.parametrize("retries", [0, 20])
def test_retries_from_0_to_20_are_taken(retries: int) -> None:
    assert _cobot({"retries": retries}).retries == retries


@pytest.mark.parametrize("retries", [-1, 21, 1.5, True, "3"])
def test_retries_outside_0_to_20_are_refused(retries: object) -> None:
    assert "'retries' must be a whole number from 0 to 20" in _refused({"retries": retries})


def test_a_task_config_that_is_not_an_object_is_refused() -> None:
    assert "'task' must be an object" in _refused(["step"])


# Guards and messages --------------------------------------------------------------------


def _silent(**keys: Any) -> Any:
    pattern = read_pattern(_doc(x1=keys))
    transition = pattern.transition("x1")
    assert transition is not None
    return transition


def test_a_silent_transition_without_guard_or_message_has_neither() -> None:
    assert guard_of(_silent()) is None
    assert message_of(_silent()) is None


def test_a_guard_is_an_expression_over_case_data() -> None:
    assert guard_of(_silent(guard="data.ok and data.count < 3")) == "data.ok and data.count < 3"


@pytest.mark.parametrize(
    ("guard", "complaint"),
    [
        ("", "'guard' must be an expression"),
        ("  ", "'guard' must be an expression"),
        (True, "'guard' must be an expression"),
        ("result.ok", "guard: unknown name 'result'"),
        ("data.ok ==", "guard:"),
    ],
)
def test_a_malformed_guard_is_refused(guard: object, complaint: str) -> None:
    with pytest.raises(ConfigError, match=r"^x1: ") as caught:
        guard_of(_silent(guard=guard))

    assert complaint in str(caught.value)


def test_a_message_has_a_name_and_correlation_expressions_over_case_data() -> None:
    message = message_of(
        _silent(message={"name": "part-arrived", "correlation": {"order": "data.order"}})
    )

    assert message is not None
    assert message.name == "part-arrived"
    assert dict(message.correlation) == {"order": "data.order"}


@pytest.mark.parametrize(
    ("message", "complaint"),
    [
        ("part-arrived", "'message' needs a 'name'"),
        ({"correlation": {}}, "'message' needs a 'name'"),
        ({"name": ""}, "'message' needs a 'name'"),
        ({"name": "m", "correlation": ["order"]}, "the message's 'correlation' maps keys"),
        ({"name": "m", "correlation": {"order": 7}}, "the message's 'correlation' maps keys"),
        ({"name": "m", "correlation": {"order": "result.order"}}, "correlation 'order': unknown"),
    ],
)
def test_a_malformed_message_is_refused(message: object, complaint: str) -> None:
    with pytest.raises(ConfigError, match=r"^x1: ") as caught:
        message_of(_silent(message=message))

    assert complaint in str(caught.value)


@pytest.mark.parametrize(
    ("key", "value"), [("guard", "data.ok"), ("message", {"name": "part-arrived"})]
)
def test_only_silent_transitions_have_a_guard_or_message(key: str, value: object) -> None:
    issues = config_issues(read_pattern(_doc(tc1={key: value})))

    assert [(i.code, i.elements) for i in issues] == [("task-config", ("tc1",))]
    assert issues[0].message == f"Task tc1: only silent transitions have a '{key}'."


# The check ------------------------------------------------------------------------------


def test_config_issues_are_task_config_errors_naming_each_transition() -> None:
    data = _doc(
        tc1={"task": {"retries": 99}},
        x1={"guard": "nope.ok"},
        to1={"task": {"form": {"type": "array"}}},
    )

    issues = config_issues(read_pattern(data))

    assert [(i.code, i.severity, i.elements) for i in issues] == [
        ("task-config", "error", ("tc1",)),
        ("task-config", "error", ("x1",)),
        ("task-config", "error", ("to1",)),
    ]
    assert [i.message.split(":")[0] for i in issues] == ["Task tc1", "Split/join x1", "Task to1"]


def test_a_well_configured_pattern_has_no_config_issues() -> None:
    data = _doc(
        tc1={"task": {"step": {"number": "=data.step"}, "outputs": {"done": "True"}}},
        x1={"message": {"name": "go", "correlation": {"id": "data.id"}}},
        to1={"task": {"form": {"type": "object"}, "timeout": 600, "retries": 0}},
    )

    assert config_issues(read_pattern(data)) == []


def test_a_guard_and_a_message_on_one_transition_are_refused() -> None:
    data = _doc(x1={"guard": "data.ok", "message": {"name": "go"}})

    [issue] = config_issues(read_pattern(data))
    assert issue.elements == ("x1",)
    assert "not both" in issue.message


def test_a_space_constraint_interrupts_only_by_pause_or_slow() -> None:
    data = two_lanes([("to1", "tc2", "space")], declared="cooperation")
    data["constraints"][0]["interrupt"] = "Slow"

    [issue] = config_issues(read_pattern(data))
    assert "'Slow'" in issue.message
    assert issue.elements == ("to1", "tc2")


def test_check_document_reports_task_config_errors() -> None:
    data = two_lanes([("to1", "tc2", "time")], declared="synchronized")
    assert check_document(data).valid
    for transition in data["processes"][0]["transitions"]:
        if transition["id"] == "tc2":
            transition["task"] = {"device": {"call": "display.show", "args": {}}}

    report = check_document(data)

    assert not report.valid
    assert report.sound is True  # a configuration fault is not a behavioural one
    assert [(e.code, e.elements) for e in report.errors] == [("task-config", ("tc2",))]
    assert "display.show takes the arguments: text" in report.errors[0].message


def test_check_document_reports_a_malformed_device_call_instead_of_failing() -> None:
    data = two_lanes([("to1", "tc2", "time")])
    for transition in data["processes"][0]["transitions"]:
        if transition["id"] == "tc2":
            transition["task"] = {"device": {"call": ["display.show"]}}

    report = check_document(data)

    assert [(e.code, e.elements) for e in report.errors] == [("task-config", ("tc2",))]


# The pattern's initial case data ------------------------------------------------------------


def test_a_pattern_without_data_starts_its_cases_empty() -> None:
    assert initial_data(read_pattern(_doc())) == {}


def test_the_patterns_data_is_what_each_case_starts_with_a_copy_each_time() -> None:
    data = _doc()
    data["data"] = {"spots": [[0.1, 0.2, 0.0, 0, 0, 0]], "done": []}
    net = CaseNet(read_pattern(data))

    first = net.initial_data()
    first["done"].append("x")

    assert net.initial_data() == {"spots": [[0.1, 0.2, 0.0, 0, 0, 0]], "done": []}
    assert config_issues(read_pattern(data)) == []


@pytest.mark.parametrize("value", [[1, 2], "spots", 3, None])
def test_data_that_is_no_json_object_is_a_task_config_error(value: object) -> None:
    data = _doc()
    data["data"] = value

    with pytest.raises(ConfigError, match="must be a JSON object"):
        initial_data(read_pattern(data))
    [issue] = config_issues(read_pattern(data))
    assert issue.code == "task-config"
    assert "'data'" in issue.message
    assert not check_document(data).valid
