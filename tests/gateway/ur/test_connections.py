"""Lost, refused, owned and silent connections: clear failures, reconnection, no hang."""

from __future__ import annotations

import asyncio
import time

import pytest

from hrc_gateway import urua
from hrc_gateway.backend import CommandFailed
from hrc_gateway.ur.backend import URBackend
from tests.gateway.fake_ur import FakeUR
from tests.gateway.ur.conftest import Published, Space, make_backend
from tests.gateway.ur.test_handshake import OUT_BIT, step


async def eventually(command: object, timeout: float = 10.0) -> None:
    """Retries a command (a zero-argument coroutine function) until it succeeds."""
    deadline = time.monotonic() + timeout
    while True:
        try:
            await command()  # type: ignore[operator]
            return
        except CommandFailed:
            if time.monotonic() > deadline:
                raise
            await asyncio.sleep(0.1)


async def test_inputs_another_client_owns_fail_start_naming_the_cause(
    fake_ur: FakeUR, published: Published
) -> None:
    fake_ur.rtde.external_owners.add("input_int_register_42")
    backend = make_backend(fake_ur)

    with pytest.raises(CommandFailed) as failure:
        await asyncio.wait_for(backend.start(Space(), published), 15)

    assert failure.value.status == "BadResourceUnavailable"
    message = str(failure.value)
    assert "Another RTDE client or a fieldbus adapter" in message
    assert "already in use" in message  # ur-rtde's own words
    await backend.close()


async def test_an_unreachable_robot_fails_start(fake_ur: FakeUR, published: Published) -> None:
    fake_ur.rtde.refuse = True
    backend = make_backend(fake_ur)

    with pytest.raises(CommandFailed) as failure:
        await asyncio.wait_for(backend.start(Space(), published), 15)

    assert failure.value.status == "BadCommunicationError"
    assert "No RTDE connection to 127.0.0.1:30004" in str(failure.value)
    await backend.close()


async def test_a_dropped_dashboard_fails_commands_clearly_then_reconnects(
    backend: URBackend, fake_ur: FakeUR
) -> None:
    fake_ur.dashboard.refuse = True
    fake_ur.drop_dashboard_connections()

    with pytest.raises(CommandFailed) as failure:
        await backend.add_to_log("after the drop")
    assert failure.value.status == "BadCommunicationError"
    assert "reconnecting" in str(failure.value)

    fake_ur.dashboard.refuse = False
    await eventually(lambda: backend.add_to_log("after the reconnect"))
    assert fake_ur.controller.log_messages == ["after the reconnect"]


async def test_a_dropped_rtde_connection_reads_disconnected_fails_steps_then_reconnects(
    ready: URBackend, published: Published, fake_ur: FakeUR
) -> None:
    fake_ur.rtde.refuse = True
    fake_ur.drop_rtde_connections()

    await published.equals(urua.STATE_ROBOT_MODE, "Disconnected")
    with pytest.raises(CommandFailed) as failure:
        await ready.write_inputs(step())
    assert failure.value.status == "BadCommunicationError"
    with pytest.raises(CommandFailed):
        await ready.set_speed_override(50.0)
    errors = [
        str(call[urua.STATE_LAST_ERROR])
        for call in published.calls
        if urua.STATE_LAST_ERROR in call
    ]
    assert any("The RTDE connection to 127.0.0.1 dropped" in e for e in errors)

    fake_ur.rtde.refuse = False
    await published.equals(urua.STATE_ROBOT_MODE, urua.ROBOT_MODE_RUNNING, timeout=15)
    await ready.write_inputs(step())
    await published.equals(OUT_BIT, True)
    assert fake_ur.controller.ran() == 1


async def test_a_dashboard_that_never_answers_fails_a_command_within_seconds(
    backend: URBackend, fake_ur: FakeUR
) -> None:
    fake_ur.dashboard.silent = True
    started = time.monotonic()

    with pytest.raises(CommandFailed) as failure:
        await asyncio.wait_for(backend.popup("anyone there?"), 15)

    assert failure.value.status == "BadCommunicationError"
    # ur-rtde's 2.5 s reply deadline, perhaps twice: the state poll may be waiting first.
    assert time.monotonic() - started < 6.0
