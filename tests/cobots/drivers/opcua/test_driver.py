"""The OPC UA driver against a real simulated gateway process, over TCP on loopback."""

from __future__ import annotations

import asyncio
import signal
import time

import pytest
from asyncua import Client, ua

from hrc.cobots.drivers.base import (
    CobotNotReady,
    CobotPaused,
    CobotStopped,
    CobotUnreachable,
    CommandRefused,
    Fence,
    InvalidCommand,
    StepCommand,
    StepTimeout,
    unreachable_message,
)
from hrc.cobots.drivers.opcua.driver import QUIET_SECONDS, OpcUaDriver
from hrc.cobots.simulated import GatewayProcess, free_port
from hrc_gateway import urua
from tests.cobots.simulator import executions, read
from tests.support.polling import until_async

# Coexistence_PickAndPlace: 1 home, 2 move to a pose in the part box (ws 0), 3 pick (2 s wait).
HOME, MOVE, PICK = 1, 2, 3
POSE = [0.05, 0.05, 0.1, 0.0, 0.0, 0.0]


async def test_a_step_runs_once_and_moves_the_arm(driver: OpcUaDriver, observer: Client) -> None:
    before = await read(observer, "Axes/ActualPositions/AxisPositions")
    result = await driver.run_step(
        StepCommand(step=MOVE, workspace=0, poses=POSE, fence=Fence(7, 1))
    )
    assert (result.outcome, result.sent) == ("ran", True)
    assert await executions(observer) == 1
    assert await read(observer, "Axes/ActualPositions/AxisPositions") != before
    # The handshake is complete: both bits are down and the token is echoed.
    assert await read(observer, urua.register_path("Inputs", "Bit64")) is False
    assert await read(observer, urua.register_path("Outputs", "Bit64")) is False
    assert await read(observer, urua.register_path("Outputs", urua.FENCE_STEP)) == 7


async def test_the_same_token_twice_runs_once(driver: OpcUaDriver, observer: Client) -> None:
    command = StepCommand(step=PICK, fence=Fence(8, 1))
    first = await driver.run_step(command)
    second = await driver.run_step(command)
    assert (first.sent, second.sent) == (True, False)
    assert second.outcome == "ran"
    assert await executions(observer) == 1


async def test_on_sent_comes_when_the_cobot_has_the_step_not_when_it_has_run(
    driver: OpcUaDriver, observer: Client
) -> None:
    await driver.call("Simulator/InjectFault", "hang-next-step", "")
    accepted = asyncio.Event()
    step = asyncio.create_task(
        driver.run_step(StepCommand(step=HOME, fence=Fence(15, 1)), on_sent=accepted.set)
    )
    await asyncio.wait_for(accepted.wait(), 10)
    assert await read(observer, urua.register_path("Inputs", urua.FENCE_STEP)) == 15
    assert not step.done()  # the step hangs: it has not run
    await driver.call("Simulator/ClearFault")
    assert (await asyncio.wait_for(step, 10)).outcome == "ran"


async def test_on_sent_is_not_called_when_nothing_is_sent(driver: OpcUaDriver) -> None:
    command = StepCommand(step=PICK, fence=Fence(16, 1))
    await driver.run_step(command)
    calls: list[None] = []
    again = await driver.run_step(command, on_sent=lambda: calls.append(None))
    assert (again.sent, calls) == (False, [])


async def test_an_older_token_is_refused_by_the_program_without_moving(
    driver: OpcUaDriver, observer: Client
) -> None:
    await driver.run_step(StepCommand(step=PICK, fence=Fence(9, 1)))
    await driver.run_step(StepCommand(step=PICK, fence=Fence(10, 1)))
    # Token 9.1 is no longer the last echoed, so the driver sends it; the program knows it.
    again = await driver.run_step(StepCommand(step=PICK, fence=Fence(9, 1)))
    assert (again.sent, again.outcome) == (True, "duplicate")
    stale = await driver.run_step(StepCommand(step=PICK, fence=Fence(10, 0)))
    assert stale.outcome == "stale"
    assert await executions(observer) == 2


async def test_an_unknown_step_is_reported_not_silently_ignored(driver: OpcUaDriver) -> None:
    result = await driver.run_step(StepCommand(step=99, fence=Fence(11, 1)))
    assert result.outcome == "unknown step"


async def test_wrong_node_ids_types_and_ranges_are_clear_errors(driver: OpcUaDriver) -> None:
    with pytest.raises(InvalidCommand, match="Int99"):
        await driver.read("Register/Inputs/Intregister/Int99")
    with pytest.raises(InvalidCommand, match="no node"):
        await driver.read("State/NoSuchThing")
    with pytest.raises(InvalidCommand, match="Int32, not a str"):
        await driver.write({"Register/Inputs/Intregister/Int24": "two"})
    with pytest.raises(InvalidCommand, match="out of range"):
        await driver.write({"Register/Inputs/Intregister/Int24": 2**40})
    with pytest.raises(InvalidCommand, match="read-only"):
        await driver.write({"Register/Outputs/Bitregister/Bit64": True})
    with pytest.raises(InvalidCommand, match="no node"):
        await driver.call("NoSuchMethod")
    with pytest.raises(ValueError, match="two poses"):
        StepCommand(step=1, fence=Fence(1), poses=[0.0] * 13)


async def test_a_refused_command_carries_the_gateways_reason(driver: OpcUaDriver) -> None:
    with pytest.raises(InvalidCommand, match="NoSuchProgram"):
        await driver.call("SelectProgram", "NoSuchProgram")
    with pytest.raises(CommandRefused, match="teach pendant"):
        await driver.call("Messaging/CloseSafetyPopup")


async def test_a_protective_stop_refuses_a_step_without_sending_it(
    driver: OpcUaDriver, observer: Client
) -> None:
    await driver.call("Simulator/InjectFault", "protective-stop", "")
    await until_async(lambda: driver.cache[urua.STATE_SAFETY_MODE] != urua.SAFETY_NORMAL)
    with pytest.raises(CobotStopped, match="protective stop") as stopped:
        await driver.run_step(StepCommand(step=HOME, fence=Fence(12, 1)))
    assert not stopped.value.transient
    assert await read(observer, urua.register_path("Inputs", "Bit64")) is False
    assert await executions(observer) == 0


async def test_a_protective_stop_during_a_step_leaves_it_in_doubt_never_hanging(
    driver: OpcUaDriver, observer: Client
) -> None:
    step = asyncio.create_task(driver.run_step(StepCommand(step=PICK, fence=Fence(13, 1))))
    await until_async(lambda: driver.cache[urua.register_path("Inputs", "Bit64")] is True)
    await driver.call("Simulator/InjectFault", "protective-stop", "")
    with pytest.raises(CobotStopped, match="in doubt"):
        await asyncio.wait_for(step, 10)
    # Nothing clears the stop but the person at the pendant (the simulator's unlock).
    await asyncio.sleep(0.3)
    assert await read(observer, urua.STATE_SAFETY_MODE) == "SAFETY_MODE_PROTECTIVE_STOP"
    await driver.call("Simulator/UnlockProtectiveStop")
    await driver.call("StartProgram")
    # Retried with the same token, the step finishes and has run once.
    result = await driver.run_step(StepCommand(step=PICK, fence=Fence(13, 1)))
    assert result.outcome == "ran"
    assert await executions(observer) == 1


async def test_a_step_that_never_finishes_times_out(driver: OpcUaDriver) -> None:
    await driver.call("Simulator/InjectFault", "hang-next-step", "")
    started = time.monotonic()
    with pytest.raises(StepTimeout, match="in doubt") as timeout:
        await driver.run_step(StepCommand(step=HOME, fence=Fence(14, 1)), timeout=1.0)
    assert time.monotonic() - started < 3
    assert timeout.value.transient
    assert timeout.value.state[urua.STATE_ROBOT_MODE] == "Running"


async def test_a_step_is_refused_when_no_program_plays(driver: OpcUaDriver) -> None:
    await driver.call("StopProgram")
    await until_async(lambda: driver.cache[urua.STATE_PROGRAM_STATE] == urua.PROGRAM_STOPPED)
    with pytest.raises(CobotNotReady, match="not Playing"):
        await driver.run_step(StepCommand(step=HOME, fence=Fence(15, 1)))


async def test_a_dead_gateway_is_a_clear_transient_error_not_a_hang() -> None:
    driver = OpcUaDriver("cobot1", f"opc.tcp://127.0.0.1:{free_port()}", connect_timeout=1.0)
    started = time.monotonic()
    with pytest.raises(CobotUnreachable, match="Cannot reach cobot cobot1") as unreachable:
        await driver.run_step(StepCommand(step=HOME, fence=Fence(16, 1)), timeout=2.0)
    assert unreachable.value.transient
    assert time.monotonic() - started < 4
    await driver.close()


async def test_a_gateway_for_another_cobot_reads_as_unreachable_and_is_named_in_the_log(
    gateway: GatewayProcess, caplog: pytest.LogCaptureFixture
) -> None:
    driver = OpcUaDriver("cobot9", gateway.endpoint, connect_timeout=1.0)
    with pytest.raises(CobotUnreachable) as unreachable:
        await driver.state()
    assert str(unreachable.value) == unreachable_message("cobot9")
    assert "no cobot named 'cobot9'" in caplog.text
    await driver.close()


async def test_the_driver_reconnects_after_dropped_connections(driver: OpcUaDriver) -> None:
    await driver.run_step(StepCommand(step=HOME, fence=Fence(17, 1)))
    await driver.call("Simulator/InjectFault", "disconnect", "")
    await until_async(lambda: not driver._alive)
    result = await driver.run_step(StepCommand(step=PICK, fence=Fence(18, 1)))
    assert result.outcome == "ran"
    ran = await driver.read("Simulator/ExecutedSteps")
    assert [line.split()[0] for line in ran] == ["17.1", "18.1"]


async def test_a_cached_state_right_after_a_call_shows_the_calls_effect(
    driver: OpcUaDriver, observer: Client
) -> None:
    await driver.call("PauseProgram")

    # The call's effect may not have come through the subscription yet: the
    # cheap read must not answer with the state from before it.
    assert (await driver.state(fresh=False))["ProgramState"] == urua.PROGRAM_PAUSED


async def test_a_cached_state_follows_what_others_do_to_the_cobot(
    driver: OpcUaDriver, observer: Client
) -> None:
    await driver.state()
    cobot = observer.get_node(urua.node_id("cobot1"))
    pause = ua.NodeId.from_string(urua.node_id("cobot1", "PauseProgram"))
    await cobot.call_method(pause)  # another client, not ours

    await until_async(lambda: driver.cache[urua.STATE_PROGRAM_STATE] == urua.PROGRAM_PAUSED)
    assert (await driver.state(fresh=False))["ProgramState"] == urua.PROGRAM_PAUSED


async def test_a_quiet_session_hears_the_heartbeat_alone_and_reads_before_its_next_step(
    driver: OpcUaDriver, observer: Client
) -> None:
    await driver.run_step(StepCommand(step=HOME, fence=Fence(19, 1)))
    await asyncio.sleep(QUIET_SECONDS + 0.5)

    # Another client pauses the program: the quiet session hears the heartbeat, not that.
    cobot = observer.get_node(urua.node_id("cobot1"))
    await cobot.call_method(ua.NodeId.from_string(urua.node_id("cobot1", "PauseProgram")))
    beat = driver.cache[urua.STATE_HEARTBEAT]
    await until_async(lambda: driver.cache[urua.STATE_HEARTBEAT] > beat + 2)
    assert await read(observer, urua.STATE_PROGRAM_STATE) == urua.PROGRAM_PAUSED
    assert driver.cache[urua.STATE_PROGRAM_STATE] == urua.PROGRAM_PLAYING

    # What it did not hear is read before anything is decided or sent.
    assert (await driver.state(fresh=False))["ProgramState"] == urua.PROGRAM_PAUSED
    with pytest.raises(CobotPaused):
        await driver.run_step(StepCommand(step=PICK, fence=Fence(20, 1)))
    assert await executions(observer) == 1

    # Its next step listens again: the acknowledgement it waits for comes by the subscription.
    await asyncio.sleep(QUIET_SECONDS + 0.5)
    await driver.call("StartProgram")
    result = await driver.run_step(StepCommand(step=PICK, fence=Fence(20, 1)))
    assert (result.outcome, result.sent) == ("ran", True)
    assert await executions(observer) == 2


async def test_a_quiet_session_whose_gateway_froze_drives_its_next_step_once(
    driver: OpcUaDriver, gateway: GatewayProcess
) -> None:
    await driver.run_step(StepCommand(step=HOME, fence=Fence(21, 1)))
    await asyncio.sleep(QUIET_SECONDS + 0.5)
    # Frozen past the heartbeat's silence: asyncua's checks give up on the subscription or on
    # the connection, and the quiet session's next step finds out and opens a new one.
    assert gateway.process is not None
    gateway.process.send_signal(signal.SIGSTOP)
    await asyncio.sleep(2.0)
    gateway.process.send_signal(signal.SIGCONT)

    result = await driver.run_step(StepCommand(step=PICK, fence=Fence(22, 1)))
    assert (result.outcome, result.sent) == ("ran", True)
    ran = await driver.read("Simulator/ExecutedSteps")
    assert [line.split()[0] for line in ran] == ["21.1", "22.1"]
