"""The backend mirrors the robot's state into URUA's paths."""

from __future__ import annotations

import asyncio

import pytest

from hrc_gateway import urua
from hrc_gateway.ur.backend import URBackend
from tests.gateway.fake_ur import FakeUR
from tests.gateway.ur.conftest import Published


async def test_start_publishes_the_robot_as_it_is(backend: URBackend, published: Published) -> None:
    values = published.values

    assert values[urua.STATE_ROBOT_MODE] == "Power Off"
    assert values[urua.STATE_SAFETY_MODE] == urua.SAFETY_NORMAL
    assert values[urua.STATE_PROGRAM_STATE] == urua.PROGRAM_STOPPED
    assert values["State/Remote"] is True
    assert values[urua.STATE_CURRENT_PROGRAM] == ""
    assert values["SafetyBoard/MainVoltage"] == pytest.approx(48.1)
    assert values["Register/Inputs/Bitregister/Bit64"] is False
    assert values["Register/Inputs/Doubleregister/Double35"] == 0.0
    assert await backend.serial_number() == "20235500123"
    assert await backend.robot_model() == "UR5"


async def test_joint_positions_and_the_tcp_pose_are_mirrored_as_vectors_and_axes(
    backend: URBackend, published: Published, fake_ur: FakeUR
) -> None:
    with fake_ur.controller.lock:
        fake_ur.controller.joints = [0.1, 0.2, 0.3, 0.4, 0.5, 0.6]
        fake_ur.controller.tcp_pose = [0.5, -0.2, 0.3, 0.0, 3.1, 0.1]

    await published.equals("Axes/ActualPositions/AxisPositions", [0.1, 0.2, 0.3, 0.4, 0.5, 0.6])

    assert published.values["Axes/ActualPositions/Axis3"] == 0.3
    # The TCP pose, not the joint velocities URUA put there.
    assert published.values["Tcp/ActualPose/TCPPose"] == [0.5, -0.2, 0.3, 0.0, 3.1, 0.1]
    assert published.values["Tcp/ActualPose/Axis5"] == 3.1


async def test_a_value_is_published_when_it_changes_and_not_again(
    backend: URBackend, published: Published, fake_ur: FakeUR
) -> None:
    calls = len(published.calls)
    with fake_ur.controller.lock:
        fake_ur.controller.joints[5] = 1.25
    await published.equals("Axes/ActualPositions/Axis6", 1.25)
    await asyncio.sleep(0.2)  # ten more snapshots at 50 Hz

    later = published.calls[calls:]
    assert sum("Axes/ActualPositions/Axis6" in call for call in later) == 1
    assert all(urua.STATE_ROBOT_MODE not in call for call in later)


async def test_programs_come_from_the_configuration_as_base_names(backend: URBackend) -> None:
    assert await backend.programs() == ["hrc_steps", "pick_and_place"]
