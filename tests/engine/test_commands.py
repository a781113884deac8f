"""A cobot task's command from its configuration and the case data (hrc.engine.commands)."""

import pytest

from hrc.engine.commands import cobot_command
from hrc.engine.runtime import RuntimeFault
from hrc.engine.taskconfig import DeviceConfig, StepConfig, TaskConfig

POSE = [0.1, 0.2, 0.3, 0.0, 3.14, 0.0]


def step(**fields: object) -> TaskConfig:
    return TaskConfig("step", step=StepConfig(**{"program": "assembly", "number": 3, **fields}))  # type: ignore[arg-type]


def test_a_step_carries_its_program_number_workspace_and_two_poses_padded_with_zeros() -> None:
    assert cobot_command("pick", step(workspace=2, poses=[POSE]), {}) == {
        "program": "assembly",
        "number": 3,
        "workspace": 2,
        "poses": POSE + [0.0] * 6,
    }


def test_a_step_without_poses_sends_twelve_zeros() -> None:
    assert cobot_command("pick", step(), {})["poses"] == [0.0] * 12  # type: ignore[typeddict-item]


def test_expressions_are_evaluated_over_the_case_data_when_the_job_queues() -> None:
    config = step(number="=data.slot + 1", workspace="=data.area", poses="=data.poses")
    data = {"slot": 4, "area": 1, "poses": [POSE, POSE]}
    command = cobot_command("place", config, data)
    assert (command["number"], command["workspace"]) == (5, 1)  # type: ignore[typeddict-item]
    assert command["poses"] == POSE + POSE  # type: ignore[typeddict-item]


def test_a_whole_float_is_a_step_number_but_a_fraction_or_a_boolean_is_not() -> None:
    assert cobot_command("pick", step(number=7.0), {})["number"] == 7  # type: ignore[typeddict-item]
    with pytest.raises(RuntimeFault, match=r"pick: the step number resolved to 2\.5"):
        cobot_command("pick", step(number=2.5), {})
    with pytest.raises(RuntimeFault, match="the step workspace resolved to True"):
        cobot_command("pick", step(workspace="=data.flag"), {"flag": True})


@pytest.mark.parametrize("poses", [[POSE, POSE, POSE], [[1.0, 2.0]], [POSE, [1.0]]])
def test_poses_that_are_not_one_or_two_six_value_poses_are_a_fault(poses: object) -> None:
    with pytest.raises(RuntimeFault, match="not one or two 6-value poses"):
        cobot_command("pick", step(poses="=data.poses"), {"poses": poses})


def test_an_expression_that_fails_is_a_fault_naming_the_task() -> None:
    with pytest.raises(RuntimeFault, match="The configuration of pick failed"):
        cobot_command("pick", step(number="=data.missing"), {})


def test_a_device_call_carries_its_method_its_arguments_in_order_and_its_output_names() -> None:
    config = TaskConfig(
        "device",
        device=DeviceConfig("linear-axis.move", {"duration_ms": "=data.ms", "direction": "left"}),
    )
    assert cobot_command("move", config, {"ms": 1500}) == {
        "method": "Devices/LinearAxis/Move",
        "args": ["left", 1500],
        "outputs": [],
    }


def test_an_operator_task_has_no_command() -> None:
    with pytest.raises(RuntimeFault, match="operator task"):
        cobot_command("count", TaskConfig("operator"), {})
