"""Why a cobot cannot take a step, in one sentence that names the state and what a person does.

One wording per state, used by the driver (which refuses to send a step to a
cobot that cannot move) and by the worker that prepares a cobot before a step
(hrc.cases.jobs), so an incident reads the same whichever of them saw it first.
The error's class says whether waiting can help: a controller on its way up or
not yet reached is transient; powering on, releasing the brakes and clearing a
stop are a person's, so they are permanent (an incident at once). hrc never
clears a protective or emergency stop and never powers a cobot on by itself.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, Final

from hrc.cobots.drivers.base import (
    CobotNotReady,
    CobotStarting,
    CobotStopped,
    CobotUnreachable,
    DriverError,
)
from hrc_gateway import urua

# On its way to Idle or Running by itself: a retry a little later may find it ready.
STARTING_MODES: Final = frozenset({"Booting", "Power On"})
# The gateway answers but has no controller behind it (cable, controller off).
NO_CONTROLLER_MODES: Final = frozenset({"No Controller", "Disconnected"})

_STOPS: Final = {
    "SAFETY_MODE_PROTECTIVE_STOP": "a protective stop",
    "SAFETY_MODE_SAFEGUARD_STOP": "a safeguard stop",
    "SAFETY_MODE_SYSTEM_EMERGENCY_STOP": "a system emergency stop",
    "SAFETY_MODE_ROBOT_EMERGENCY_STOP": "an emergency stop",
}


def page_of(cobot_id: int) -> str:
    """The cobot's page in hrc, where engineers and admins power it on or release its brakes."""
    return f"/cobots/{cobot_id}/"


def not_ready(
    name: str,
    state: Mapping[str, Any],
    *,
    page: str = "",
    endpoint: str = "",
) -> DriverError | None:
    """Why a cobot in `state` (RobotMode and SafetyMode, by their short names) cannot move under
    program control; None when its arm can (the program is the caller's concern).

    `page` (page_of) and `endpoint` make the sentence name where a person acts; without them
    it says "its page in hrc" and "its gateway".
    """
    safety = state.get("SafetyMode")
    mode = state.get("RobotMode")
    where = f"from its page ({page})" if page else "from its page in hrc"
    if safety not in urua.SAFETY_MODES_THAT_MOVE:
        stop = _STOPS.get(str(safety), f"safety mode {safety!r}")
        return CobotStopped(
            f"{name} is in {stop} ({safety}): a person must check the cell and clear it at the "
            "teach pendant; hrc never clears it.",
            state=state,
        )
    if mode == urua.ROBOT_MODE_RUNNING:
        return None
    if mode == urua.ROBOT_MODE_POWER_OFF:
        return CobotNotReady(
            f"{name} is powered off: power it on at the pendant or {where}.", state=state
        )
    if mode == urua.ROBOT_MODE_IDLE:
        return CobotNotReady(
            f"{name} is powered on with its brakes engaged (Idle): release the brakes at the "
            f"pendant or {where}.",
            state=state,
        )
    if mode in STARTING_MODES:
        return CobotStarting(
            f"{name} is starting up ({mode}); the step is tried again while its retries last.",
            state=state,
        )
    if mode in NO_CONTROLLER_MODES:
        return CobotUnreachable(
            f"{name}'s gateway ({endpoint or 'its endpoint'}) reports {mode!r}: no robot "
            "controller answers behind it; check the controller and its cable to the gateway.",
            state=state,
        )
    return CobotNotReady(
        f"{name} is in robot mode {mode!r}, not Running: a person must bring it to Running at "
        "the pendant.",
        state=state,
    )
