"""URUA's four-way step handshake, emulated over frames, against the fake's step program."""

from __future__ import annotations

import asyncio

import pytest

from hrc_gateway import urua
from hrc_gateway.backend import CommandFailed, RegisterValue
from hrc_gateway.ur import protocol
from hrc_gateway.ur.backend import URBackend
from tests.gateway.fake_ur import FakeUR
from tests.gateway.ur.conftest import Published, Space, make_backend

OUT_BIT = urua.register_path("Outputs", "Bit64")
OUT_STEP = urua.register_path("Outputs", "Int24")
OUT_STEP_ID = urua.register_path("Outputs", "Int26")
OUT_ATTEMPT = urua.register_path("Outputs", "Int27")
OUT_OUTCOME = urua.register_path("Outputs", "Int28")
POSES = [0.01 * n for n in range(12)]


def step(number: int = 3, token: tuple[int, int] = (17, 1)) -> dict[str, RegisterValue]:
    """One client write request: step, workspace, token, poses and Bit64 raised."""
    values: dict[str, RegisterValue] = {"Int24": number, "Int25": 1}
    values |= {"Int26": token[0], "Int27": token[1]}
    values |= dict(zip(urua.POSE_REGISTERS, POSES, strict=True))
    return values | {"Bit64": True}


async def cycle(backend: URBackend, published: Published, values: dict[str, RegisterValue]) -> int:
    """A whole handshake; returns the outcome the program reported."""
    await backend.write_inputs(values)
    await published.equals(OUT_BIT, True)
    outcome = published.values[OUT_OUTCOME]
    await backend.write_inputs({"Bit64": False})
    await published.equals(OUT_BIT, False)
    assert isinstance(outcome, int)
    return outcome


async def test_the_handshake_runs_the_step_once_and_publishes_its_outputs_before_bit64(
    ready: URBackend, published: Published, fake_ur: FakeUR
) -> None:
    await ready.write_inputs(step(3, (17, 1)))
    await published.equals(OUT_BIT, True)

    assert published.values[OUT_STEP] == 3
    assert published.values[OUT_STEP_ID] == 17
    assert published.values[OUT_ATTEMPT] == 1
    assert published.values[OUT_OUTCOME] == urua.OUTCOME_RAN
    assert published.index(OUT_OUTCOME, urua.OUTCOME_RAN) < published.index(OUT_BIT, True)
    [execution] = fake_ur.controller.executions
    assert (execution.step, execution.workspace, execution.token) == (3, 1, (17, 1))
    assert execution.poses == pytest.approx(POSES)

    await ready.write_inputs({"Bit64": False})
    await published.equals(OUT_BIT, False)
    assert published.values["Register/Inputs/Bitregister/Bit64"] is False


async def test_a_redelivered_token_is_acknowledged_as_a_duplicate_without_being_sent(
    ready: URBackend, published: Published, fake_ur: FakeUR
) -> None:
    await cycle(ready, published, step(3, (17, 2)))
    frames_sent = fake_ur.controller.input_int(protocol.IN_SEQ)

    assert await cycle(ready, published, step(3, (17, 2))) == urua.OUTCOME_DUPLICATE
    assert await cycle(ready, published, step(3, (17, 1))) == urua.OUTCOME_STALE

    assert fake_ur.controller.input_int(protocol.IN_SEQ) == frames_sent
    assert fake_ur.controller.ran() == 1


async def test_the_program_fences_a_token_the_gateway_no_longer_holds(
    ready: URBackend, published: Published, fake_ur: FakeUR
) -> None:
    await cycle(ready, published, step(3, (17, 1)))
    await cycle(ready, published, step(4, (18, 1)))
    frames_sent = fake_ur.controller.input_int(protocol.IN_SEQ)

    assert await cycle(ready, published, step(3, (17, 1))) == urua.OUTCOME_DUPLICATE

    assert fake_ur.controller.input_int(protocol.IN_SEQ) > frames_sent  # it was sent
    assert fake_ur.controller.ran() == 2


async def test_steps_without_a_token_run_every_time(
    ready: URBackend, published: Published, fake_ur: FakeUR
) -> None:
    for _ in range(2):
        assert await cycle(ready, published, step(3, (0, 0))) == urua.OUTCOME_RAN

    assert fake_ur.controller.ran() == 2


async def test_registers_the_protocol_cannot_carry_are_refused_and_nothing_is_applied(
    ready: URBackend, published: Published, fake_ur: FakeUR
) -> None:
    with pytest.raises(CommandFailed) as failure:
        await ready.write_inputs({"Int24": 5, "Int0": 1, "Bit65": True, "Bit64": True})

    assert failure.value.status == "BadNotSupported"
    message = str(failure.value)
    assert "Int0, Bit65" in message
    assert "Bit64, Int24–Int27 and Double24–Double35" in message
    assert published.values["Register/Inputs/Intregister/Int24"] == 0
    assert published.values["Register/Inputs/Bitregister/Bit64"] is False
    await asyncio.sleep(0.05)
    assert fake_ur.controller.input_int(protocol.IN_SEQ) == 0  # only the reset frame


async def test_a_step_is_refused_while_no_program_plays(
    backend: URBackend, published: Published
) -> None:
    with pytest.raises(CommandFailed) as failure:
        await backend.write_inputs(step())

    assert failure.value.status == "BadInvalidState"
    assert "not Playing" in str(failure.value)
    assert published.values["Register/Inputs/Bitregister/Bit64"] is False


async def test_a_step_is_refused_when_the_playing_program_is_not_a_step_program(
    fake_ur: FakeUR, published: Published
) -> None:
    fake_ur.controller.make_ready("not_hrc.urp")
    backend = make_backend(fake_ur)
    await backend.start(Space(), published)
    try:
        with pytest.raises(CommandFailed, match="does not speak the HRC frame protocol"):
            await backend.write_inputs(step())
    finally:
        await backend.close()


async def test_bit64_cleared_early_leaves_output_bit64_low_and_a_new_step_waits(
    ready: URBackend, published: Published, fake_ur: FakeUR
) -> None:
    fake_ur.controller.step_duration = 0.5
    await ready.write_inputs(step(3, (17, 1)))
    await ready.write_inputs({"Bit64": False})

    with pytest.raises(CommandFailed, match="still in flight"):
        await ready.write_inputs(step(4, (18, 1)))
    await published.equals(OUT_OUTCOME, urua.OUTCOME_RAN)

    assert published.values[OUT_BIT] is False
    assert fake_ur.controller.ran() == 1


async def test_a_protective_stop_during_a_step_is_reported_and_the_step_ends_after_resume(
    ready: URBackend, published: Published, fake_ur: FakeUR
) -> None:
    fake_ur.controller.step_duration = 0.3
    await ready.write_inputs(step(3, (17, 1)))
    await fake_ur.until(lambda c: c.program.running is not None)

    fake_ur.controller.protective_stop()
    error = await published.until(urua.STATE_LAST_ERROR, lambda v: "suspended" in str(v))
    assert "SAFETY_MODE_PROTECTIVE_STOP" in str(error)
    assert "teach pendant" in str(error)
    assert published.values[OUT_BIT] is False

    fake_ur.controller.clear_protective_stop()  # the person at the pendant
    await ready.play()
    await published.equals(OUT_BIT, True)
    assert fake_ur.controller.ran() == 1
    assert not [c for c in fake_ur.controller.dashboard_commands if "protective" in c]


async def test_a_step_that_never_finishes_times_out_and_a_late_acknowledgement_still_counts(
    fake_ur: FakeUR, published: Published
) -> None:
    fake_ur.controller.make_ready()
    fake_ur.controller.hang_steps = {5}
    backend = make_backend(fake_ur, command_timeout=0.5)
    await backend.start(Space(), published)
    try:
        await backend.write_inputs(step(5, (30, 1)))
        error = await published.until(urua.STATE_LAST_ERROR, lambda v: "within 0.5 s" in str(v))
        assert "Step 5 (token 30/1)" in str(error)
        assert published.values[OUT_BIT] is False

        with fake_ur.controller.lock:  # the step finishes after all
            running = fake_ur.controller.program.running
            assert running is not None
            running.remaining = 0.0
        await published.equals(OUT_BIT, True)
        assert published.values[OUT_OUTCOME] == urua.OUTCOME_RAN
    finally:
        await backend.close()


async def test_stopping_the_program_during_a_step_ends_the_wait_at_once(
    ready: URBackend, published: Published, fake_ur: FakeUR
) -> None:
    fake_ur.controller.step_duration = 10.0
    await ready.write_inputs(step(3, (17, 1)))
    await fake_ur.until(lambda c: c.program.running is not None)

    await ready.stop_program()

    await published.until(urua.STATE_LAST_ERROR, lambda v: "program was stopped" in str(v), 1.0)
    assert fake_ur.controller.ran() == 0
