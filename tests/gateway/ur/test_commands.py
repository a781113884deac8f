"""URUA's methods, carried out through the dashboard server (and the speed slider over RTDE)."""

from __future__ import annotations

import pytest

from hrc_gateway import urua
from hrc_gateway.backend import CommandFailed
from hrc_gateway.ur.backend import URBackend
from tests.gateway.fake_ur import FakeUR
from tests.gateway.fake_ur.controller import IDLE, POWER_OFF, RUNNING
from tests.gateway.ur.conftest import Published

# What the software must never send: only a person at the pendant clears these.
NEVER_SENT = ("unlock protective stop", "close safety popup", "restart safety")


async def test_power_on_powers_up_waits_for_idle_then_releases_the_brakes(
    backend: URBackend, published: Published, fake_ur: FakeUR
) -> None:
    await backend.power_on()

    assert fake_ur.controller.robot_mode == RUNNING
    sent = fake_ur.controller.dashboard_commands
    assert sent.index("power on") < sent.index("brake release")
    await published.equals(urua.STATE_ROBOT_MODE, urua.ROBOT_MODE_RUNNING)


async def test_power_on_of_a_running_robot_sends_nothing(ready: URBackend, fake_ur: FakeUR) -> None:
    await ready.power_on()

    assert "power on" not in fake_ur.controller.dashboard_commands


async def test_brake_release_from_idle_sends_brake_release_and_waits_for_running(
    backend: URBackend, published: Published, fake_ur: FakeUR
) -> None:
    fake_ur.controller.robot_mode = IDLE  # powered on at the pendant, brakes still on

    await backend.brake_release()

    assert fake_ur.controller.robot_mode == RUNNING
    assert "brake release" in fake_ur.controller.dashboard_commands
    assert "power on" not in fake_ur.controller.dashboard_commands
    await published.equals(urua.STATE_ROBOT_MODE, urua.ROBOT_MODE_RUNNING)


async def test_brake_release_of_a_powered_off_robot_is_refused_without_a_command(
    backend: URBackend, fake_ur: FakeUR
) -> None:
    with pytest.raises(CommandFailed, match="Power it on first") as refused:
        await backend.brake_release()

    assert refused.value.status == "BadInvalidState"
    assert "brake release" not in fake_ur.controller.dashboard_commands
    assert fake_ur.controller.robot_mode == POWER_OFF


async def test_brake_release_in_a_protective_stop_is_refused_and_never_unlocks(
    backend: URBackend, fake_ur: FakeUR
) -> None:
    fake_ur.controller.robot_mode = IDLE
    fake_ur.controller.protective_stop()

    with pytest.raises(CommandFailed, match="teach pendant"):
        await backend.brake_release()

    assert not set(NEVER_SENT) & set(fake_ur.controller.dashboard_commands)
    assert "brake release" not in fake_ur.controller.dashboard_commands


async def test_a_loaded_program_plays(
    backend: URBackend, published: Published, fake_ur: FakeUR
) -> None:
    await backend.power_on()

    await backend.load_program("hrc_steps")
    await backend.play()

    await published.equals(urua.STATE_PROGRAM_STATE, urua.PROGRAM_PLAYING)
    await published.equals(urua.STATE_CURRENT_PROGRAM, "/programs/hrc_steps.urp")
    await published.equals("State/RobotState", "PLAYING hrc_steps.urp")
    assert "load hrc_steps.urp" in fake_ur.controller.dashboard_commands


async def test_loading_a_missing_program_is_not_found_in_the_dashboards_words(
    backend: URBackend,
) -> None:
    with pytest.raises(CommandFailed) as failure:
        await backend.load_program("nope")

    assert failure.value.status == "BadNotFound"
    assert "File not found: nope.urp" in str(failure.value)


async def test_commands_in_local_control_say_remote_control_is_needed(
    backend: URBackend, fake_ur: FakeUR
) -> None:
    fake_ur.controller.remote_control = False

    with pytest.raises(CommandFailed) as failure:
        await backend.load_program("hrc_steps")

    assert failure.value.status == "BadInvalidState"
    assert "Local Control" in str(failure.value)
    assert "Remote Control" in str(failure.value)


async def test_play_without_power_is_refused_with_the_robots_reply(backend: URBackend) -> None:
    await backend.load_program("hrc_steps")

    with pytest.raises(CommandFailed, match="Failed to execute: play") as failure:
        await backend.play()

    assert failure.value.status == "BadInvalidState"


@pytest.mark.parametrize("command", ["power_on", "play"])
async def test_a_protective_stop_refuses_commands_that_would_move_and_is_never_cleared(
    backend: URBackend, fake_ur: FakeUR, command: str
) -> None:
    await backend.load_program("hrc_steps")
    fake_ur.controller.protective_stop()

    with pytest.raises(CommandFailed) as failure:
        await getattr(backend, command)()

    assert failure.value.status == "BadInvalidState"
    assert "PROTECTIVE_STOP" in str(failure.value)
    assert "teach pendant" in str(failure.value)
    sent = fake_ur.controller.dashboard_commands
    assert "power on" not in sent
    assert "play" not in sent
    assert not [c for c in sent if c.startswith(NEVER_SENT)]


async def test_pause_and_stop(ready: URBackend, published: Published) -> None:
    await ready.pause()
    await published.equals(urua.STATE_PROGRAM_STATE, urua.PROGRAM_PAUSED)

    await ready.stop_program()
    await published.equals(urua.STATE_PROGRAM_STATE, urua.PROGRAM_STOPPED)


async def test_operational_mode_popup_and_log_reach_the_pendant(
    backend: URBackend, published: Published, fake_ur: FakeUR
) -> None:
    await backend.set_operational_mode("MANUAL")
    await backend.popup("Please load the fixture")
    await backend.add_to_log("cycle 12 done")

    assert fake_ur.controller.operational_mode == "MANUAL"
    assert fake_ur.controller.popup_text == "Please load the fixture"
    assert fake_ur.controller.log_messages == ["cycle 12 done"]
    await published.equals("State/OperationalMode", "MANUAL")

    await backend.popup(None)
    await backend.set_operational_mode(None)
    assert fake_ur.controller.popup_text is None


async def test_a_message_with_a_line_break_is_refused_before_it_reaches_the_dashboard(
    backend: URBackend, fake_ur: FakeUR
) -> None:
    with pytest.raises(CommandFailed) as failure:
        await backend.popup("hello\npower off")

    assert failure.value.status == "BadInvalidArgument"
    assert not [c for c in fake_ur.controller.dashboard_commands if c.startswith("popup")]


async def test_the_speed_override_sets_the_slider_and_reads_back(
    backend: URBackend, published: Published, fake_ur: FakeUR
) -> None:
    await backend.set_speed_override(40.0)

    await fake_ur.until(lambda c: c.speed_slider == pytest.approx(0.4))
    await published.until("State/Override", lambda v: v == pytest.approx(40.0))
    with pytest.raises(CommandFailed) as failure:
        await backend.set_speed_override(140.0)
    assert failure.value.status == "BadOutOfRange"
