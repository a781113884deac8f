"""One sentence per cobot state that keeps it from a step: the cause, the remedy, and whether
waiting can help."""

from __future__ import annotations

import pytest

from hrc.cobots.drivers.base import CobotNotReady, CobotStarting, CobotStopped, CobotUnreachable
from hrc.cobots.drivers.readiness import not_ready, page_of

NORMAL = "SAFETY_MODE_NORMAL"


def _state(mode: str, safety: str = NORMAL) -> dict[str, str]:
    return {"RobotMode": mode, "SafetyMode": safety}


def test_a_running_cobot_in_a_safety_mode_that_moves_is_ready() -> None:
    assert not_ready("cobot1", _state("Running")) is None
    assert not_ready("cobot1", _state("Running", "SAFETY_MODE_REDUCED")) is None


def test_a_powered_off_cobot_is_for_a_person_at_the_pendant_or_on_its_page() -> None:
    problem = not_ready("cobot1", _state("Power Off"), page=page_of(7))
    assert isinstance(problem, CobotNotReady)
    assert not problem.transient
    assert str(problem) == (
        "cobot1 is powered off: power it on at the pendant or from its page (/cobots/7/)."
    )


def test_an_idle_cobot_needs_its_brakes_released_by_a_person() -> None:
    problem = not_ready("cobot1", _state("Idle"))
    assert isinstance(problem, CobotNotReady)
    assert not problem.transient
    assert "release the brakes at the pendant or from its page in hrc" in str(problem)


@pytest.mark.parametrize("mode", ["Booting", "Power On"])
def test_a_cobot_on_its_way_up_is_tried_again(mode: str) -> None:
    problem = not_ready("cobot1", _state(mode))
    assert isinstance(problem, CobotStarting)
    assert problem.transient


@pytest.mark.parametrize(
    ("safety", "named"),
    [
        ("SAFETY_MODE_PROTECTIVE_STOP", "a protective stop"),
        ("SAFETY_MODE_SAFEGUARD_STOP", "a safeguard stop"),
        ("SAFETY_MODE_ROBOT_EMERGENCY_STOP", "an emergency stop"),
        ("SAFETY_MODE_SYSTEM_EMERGENCY_STOP", "a system emergency stop"),
    ],
)
def test_a_stop_is_for_a_person_and_never_cleared_by_hrc(safety: str, named: str) -> None:
    problem = not_ready("cobot1", _state("Running", safety))  # whatever its robot mode
    assert isinstance(problem, CobotStopped)
    assert not problem.transient
    assert str(problem).startswith(f"cobot1 is in {named} ({safety}): a person must check")
    assert str(problem).endswith("hrc never clears it.")


@pytest.mark.parametrize("mode", ["No Controller", "Disconnected"])
def test_a_gateway_without_its_controller_names_the_endpoint_and_is_retried(mode: str) -> None:
    problem = not_ready("cobot1", _state(mode), endpoint="opc.tcp://10.0.0.5:4840")
    assert isinstance(problem, CobotUnreachable)
    assert problem.transient
    assert "opc.tcp://10.0.0.5:4840" in str(problem)


def test_the_error_carries_the_state_for_the_incident() -> None:
    problem = not_ready("cobot1", _state("Power Off"))
    assert problem is not None
    assert problem.state == _state("Power Off")
