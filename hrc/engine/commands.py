"""A cobot task's command, built from its configuration and the case data at the moment it queues.

The command is what a job stores and a worker sends: the expressions in the
task's step (its poses, number, workspace) or device call are evaluated here,
once, so a retry sends exactly what the first try did.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, TypedDict

from hrc.engine.runtime import RuntimeFault, resolve
from hrc.engine.taskconfig import MAX_POSES, POSE_LENGTH, TaskConfig


class StepCommand(TypedDict):
    """One step of the cobot's program: its number, workspace and two poses, padded with zeros."""

    program: str
    number: int
    workspace: int
    poses: list[float]


class DeviceCommand(TypedDict):
    """A gateway method under Devices/, its arguments in order, and the names of its outputs."""

    method: str
    args: list[Any]
    outputs: list[str]


def cobot_command(
    task: str, config: TaskConfig, data: Mapping[str, Any]
) -> StepCommand | DeviceCommand:
    """The command of cobot task `task` over the case data `data`.

    Raises RuntimeFault when an expression fails, the poses are not one or two
    6-value poses, or the step number or workspace is not a whole number.
    """
    if config.device is not None:
        device = config.device
        args = [resolve(task, device.args[name], data) for name in device.argument_names]
        return {"method": device.method, "args": args, "outputs": list(device.output_names)}
    if config.step is None:
        raise RuntimeFault(f"{task} is an operator task: it has no cobot command.")
    step = config.step
    return {
        "program": step.program,
        "number": _whole(task, "number", resolve(task, step.number, data)),
        "workspace": _whole(task, "workspace", resolve(task, step.workspace, data)),
        "poses": _poses(task, resolve(task, step.poses, data)),
    }


def _poses(task: str, poses: Any) -> list[float]:
    """The poses flattened and padded to MAX_POSES poses; the registers always take all of them."""
    flat = [float(v) for pose in poses for v in pose] if poses else []
    if len(flat) > MAX_POSES * POSE_LENGTH or len(flat) % POSE_LENGTH:
        raise RuntimeFault(
            f"{task}: the poses resolved to {poses!r}, not one or two 6-value poses."
        )
    return flat + [0.0] * (MAX_POSES * POSE_LENGTH - len(flat))


def _whole(task: str, what: str, value: Any) -> int:
    if isinstance(value, bool) or not isinstance(value, int | float) or int(value) != value:
        raise RuntimeFault(f"{task}: the step {what} resolved to {value!r}, not a whole number.")
    return int(value)
