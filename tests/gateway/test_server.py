"""The gateway as a prototype client sees it: URUA's node ids over real OPC UA on loopback.

The gateway runs in the test's event loop with the simulated backend; the
client is plain asyncua, doing what the prototype's client service did.
"""

from __future__ import annotations

import asyncio
from collections.abc import AsyncIterator
from pathlib import Path

import pytest
from asyncua import Client, ua

from hrc_gateway import urua
from hrc_gateway.server import Gateway, GatewayError
from hrc_gateway.sim.backend import SimBackend
from tests.support.polling import until_async


@pytest.fixture
async def gateway(tmp_path: Path) -> AsyncIterator[Gateway]:
    backend = SimBackend("cobot1", time_scale=0.05, state_file=tmp_path / "sim.json", seed=1)
    gateway = Gateway("cobot1", backend, port=0)
    await gateway.start()
    yield gateway
    await gateway.stop()


@pytest.fixture
async def client(gateway: Gateway) -> AsyncIterator[Client]:
    client = Client(gateway.endpoint)
    await client.connect()
    yield client
    await client.disconnect()


def node(client: Client, node_id: str):  # type: ignore[no-untyped-def]
    return client.get_node(node_id)


async def test_node_ids_are_urua_s(client: Client) -> None:
    for node_id in [
        "ns=2;s=cobot1",
        "ns=2;s=/cobot1/PowerOn",
        "ns=2;s=/cobot1/SelectProgram",
        "ns=2;s=/cobot1/StartProgram",
        "ns=2;s=/cobot1/State/RobotMode",
        "ns=2;s=/cobot1/State/ProgramState",
        "ns=2;s=/cobot1/State/SafetyMode",
        "ns=2;s=cobot1/Axes",
        "ns=2;s=/cobot1/Axes/ActualPositions/Axis1",
        "ns=2;s=cobot1/Tcp",
        "ns=2;s=/cobot1/Tcp/ActualPose/TCPPose",
        "ns=2;s=cobot1/Register",
        "ns=2;s=/cobot1/Register/Inputs/Bitregister/Bit64",
        "ns=2;s=/cobot1/Register/Inputs/Bitregister/Bit127",
        "ns=2;s=/cobot1/Register/Inputs/Intregister/Int0",
        "ns=2;s=/cobot1/Register/Inputs/Intregister/Int24",
        "ns=2;s=/cobot1/Register/Inputs/Doubleregister/Double24",
        "ns=2;s=/cobot1/Register/Inputs/Doubleregister/Double47",
        "ns=2;s=/cobot1/Register/Outputs/Bitregister/Bit64",
        "ns=2;s=/cobot1/Register/Outputs/Intregister/Int24",
        "ns=2;s=/cobot1/Programs/Programs",
        "ns=2;s=/cobot1/RobotMode/ManualMode",
        "ns=2;s=/cobot1/Messaging/PopupMessage",
    ]:
        assert (await node(client, node_id).read_browse_name()).Name, node_id
    root = node(client, "ns=2;s=cobot1")
    names = {child.BrowseName.Name for child in await root.get_children_descriptions()}
    assert {"PowerOn", "State", "Axes", "Tcp", "Register", "Programs", "SerialNumber"} <= names


async def test_the_prototype_client_service_handshake_completes(client: Client) -> None:
    """What client_service.rb did (§2.3), which URUA could never complete."""
    root = node(client, "ns=2;s=cobot1")
    await root.call_method("2:PowerOn")
    await root.call_method(
        "2:SelectProgram", "/home/cobot/ursim-5.11.5.1010327/programs/Coexistence_PickAndPlace"
    )
    await root.call_method("2:StartProgram")
    assert await node(client, "ns=2;s=/cobot1/State/ProgramState").read_value() == "Playing"
    step = node(client, "ns=2;s=/cobot1/Register/Inputs/Intregister/Int24")
    bit_in = node(client, "ns=2;s=/cobot1/Register/Inputs/Bitregister/Bit64")
    bit_out = node(client, "ns=2;s=/cobot1/Register/Outputs/Bitregister/Bit64")
    await step.write_value(ua.Variant(3, ua.VariantType.Int32))
    await bit_in.write_value(True)
    await _poll(bit_out, True)
    await bit_in.write_value(False)
    await _poll(bit_out, False)
    assert await node(client, "ns=2;s=/cobot1/Simulator/Executions").read_value() == 1
    outcome = node(client, "ns=2;s=/cobot1/Register/Outputs/Intregister/Int28")
    assert await outcome.read_value() == urua.OUTCOME_RAN


async def test_select_program_takes_a_name_with_or_without_directory_and_urp(
    client: Client,
) -> None:
    root = node(client, "ns=2;s=cobot1")
    current = node(client, "ns=2;s=/cobot1/State/CurrentProgram")
    for name in [
        "Collaboration_Fixture",
        "Collaboration_Fixture.urp",
        "/programs/Collaboration_Fixture.urp",
    ]:
        await root.call_method("2:SelectProgram", name)
        assert "Collaboration_Fixture" in await current.read_value()


async def test_a_failed_command_answers_bad_with_a_message(client: Client) -> None:
    root = node(client, "ns=2;s=cobot1")
    with pytest.raises(ua.UaStatusCodeError) as refused:
        await root.call_method("2:StartProgram")  # not powered, nothing loaded
    assert ua.StatusCode(refused.value.code).is_bad()
    message = await node(client, "ns=2;s=/cobot1/State/LastError").read_value()
    assert message.startswith("StartProgram:")
    with pytest.raises(ua.UaStatusCodeError, match="BadNotFound"):
        await root.call_method("2:SelectProgram", "NoSuchProgram")
    assert "NoSuchProgram" in await node(client, "ns=2;s=/cobot1/State/LastError").read_value()
    with pytest.raises(ua.UaStatusCodeError, match="BadTypeMismatch"):
        await root.call_method("2:SelectProgram", ua.Variant(3, ua.VariantType.Int32))


async def test_last_error_is_cleared_by_its_own_commands_success_not_by_anothers(
    client: Client,
) -> None:
    # A device call refused on one session while the cobot's commands succeed on another: the
    # refused caller reads LastError for why after its answer, so no other success may wipe it.
    root = node(client, "ns=2;s=cobot1")
    last_error = node(client, "ns=2;s=/cobot1/State/LastError")
    with pytest.raises(ua.UaStatusCodeError, match="BadNotFound"):
        await root.call_method("2:SelectProgram", "NoSuchProgram")
    await root.call_method("2:PowerOn")
    assert "NoSuchProgram" in await last_error.read_value()
    await root.call_method("2:SelectProgram", "Collaboration_Fixture")
    assert await last_error.read_value() == ""


async def test_brake_release_is_a_method_of_its_own_that_powering_on_does_not_need(
    client: Client,
) -> None:
    root = node(client, "ns=2;s=cobot1")
    mode = node(client, "ns=2;s=/cobot1/State/RobotMode")
    with pytest.raises(ua.UaStatusCodeError, match="BadInvalidState"):
        await root.call_method("2:BrakeRelease")  # powered off: the brakes stay on
    assert "Power it on first" in await node(client, "ns=2;s=/cobot1/State/LastError").read_value()
    assert await mode.read_value() == "Power Off"

    await root.call_method("2:PowerOn")  # as in URUA: powers on and releases the brakes
    assert await mode.read_value() == "Running"
    await root.call_method("2:BrakeRelease")
    assert await mode.read_value() == "Running"


async def test_the_gateway_never_closes_a_safety_popup(client: Client) -> None:
    messaging = node(client, "ns=2;s=/cobot1/Messaging")
    with pytest.raises(ua.UaStatusCodeError, match="BadUserAccessDenied"):
        await messaging.call_method("2:CloseSafetyPopup")


async def test_bad_writes_are_refused_with_the_reason(client: Client) -> None:
    step = node(client, "ns=2;s=/cobot1/Register/Inputs/Intregister/Int24")
    with pytest.raises(ua.UaStatusCodeError, match="BadTypeMismatch"):
        await step.write_value(ua.Variant("two", ua.VariantType.String))
    assert (
        "Int24 holds an Int32" in await node(client, "ns=2;s=/cobot1/State/LastError").read_value()
    )
    with pytest.raises(ua.UaStatusCodeError, match="BadNodeIdUnknown"):
        await node(client, "ns=2;s=/cobot1/Register/Inputs/Intregister/Int48").write_value(
            ua.Variant(1, ua.VariantType.Int32)
        )
    with pytest.raises(ua.UaStatusCodeError, match="BadNotWritable"):
        await node(client, "ns=2;s=/cobot1/Register/Outputs/Bitregister/Bit64").write_value(True)
    with pytest.raises(ua.UaStatusCodeError, match="BadOutOfRange"):
        await node(client, "ns=2;s=/cobot1/Register/Inputs/Doubleregister/Double24").write_value(
            float("nan")
        )
    # Any integer width is accepted for an Int register (asyncua's default is Int64).
    await step.write_value(ua.Variant(2, ua.VariantType.Int64))
    assert await step.read_value() == 2


async def test_one_bad_register_in_a_request_applies_none_of_them(client: Client) -> None:
    step = node(client, "ns=2;s=/cobot1/Register/Inputs/Intregister/Int24")
    bit = node(client, "ns=2;s=/cobot1/Register/Inputs/Bitregister/Bit64")
    pose = node(client, "ns=2;s=/cobot1/Register/Inputs/Doubleregister/Double24")
    results = await client.write_values(
        [step, pose, bit],
        [
            ua.DataValue(ua.Variant(5, ua.VariantType.Int32)),
            ua.DataValue(ua.Variant("x", ua.VariantType.String)),
            ua.DataValue(ua.Variant(True, ua.VariantType.Boolean)),
        ],
        raise_on_partial_error=False,
    )
    assert [r.is_bad() for r in results] == [True, True, True]
    assert await step.read_value() == 0
    assert await bit.read_value() is False
    assert (
        "Nothing in this write request was applied"
        in await node(client, "ns=2;s=/cobot1/State/LastError").read_value()
    )


async def test_values_are_pushed_on_change(client: Client) -> None:
    changes: asyncio.Queue[object] = asyncio.Queue()

    class Handler:
        def datachange_notification(self, node: object, value: object, data: object) -> None:
            changes.put_nowait(value)

    subscription = await client.create_subscription(0, Handler())
    await subscription.subscribe_data_change(node(client, "ns=2;s=/cobot1/State/RobotMode"))
    assert await asyncio.wait_for(changes.get(), 2) == "Power Off"
    await node(client, "ns=2;s=cobot1").call_method("2:PowerOn")
    seen = [await asyncio.wait_for(changes.get(), 5) for _ in range(2)]
    while seen[-1] != "Running":
        seen.append(await asyncio.wait_for(changes.get(), 5))
    assert "Idle" in seen
    await subscription.delete()


def test_insecure_is_refused_off_loopback(tmp_path: Path) -> None:
    backend = SimBackend("cobot1", state_file=tmp_path / "sim.json")
    with pytest.raises(GatewayError, match="loopback"):
        Gateway("cobot1", backend, host="0.0.0.0", secure=None)


async def _poll(variable, expected: object, timeout: float = 10) -> None:  # type: ignore[no-untyped-def]
    # The prototype polled every 0.5 s; a shorter period keeps the test quick.
    async def reached() -> bool:
        return bool(await variable.read_value() == expected)

    await until_async(reached, timeout, 0.02, f"{variable} never became {expected!r}")


async def test_an_ipv4_mapped_loopback_host_is_served_as_plain_ipv4(tmp_path: Path) -> None:
    backend = SimBackend("cobot1", state_file=tmp_path / "sim.json", time_scale=0)
    gateway = Gateway("cobot1", backend, host="::ffff:127.0.0.1", port=0)
    await gateway.start()
    try:
        assert gateway.endpoint.startswith("opc.tcp://127.0.0.1:")
        async with Client(gateway.endpoint) as client:
            mode = client.get_node(urua.node_id("cobot1", urua.STATE_ROBOT_MODE))
            assert await mode.read_value()
    finally:
        await gateway.stop()


def test_an_ipv6_host_is_written_in_brackets_in_the_endpoint(tmp_path: Path) -> None:
    backend = SimBackend("cobot1", state_file=tmp_path / "sim.json")
    assert Gateway("cobot1", backend, host="[::1]", port=4841).endpoint == "opc.tcp://[::1]:4841"


@pytest.mark.parametrize("host", ["a:b", "exa mple", "::ffff:127.0.0.1:80"])
def test_a_host_that_is_no_host_is_refused_with_a_message(tmp_path: Path, host: str) -> None:
    backend = SimBackend("cobot1", state_file=tmp_path / "sim.json")
    with pytest.raises(GatewayError, match="neither a host name nor an IP address"):
        Gateway("cobot1", backend, host=host, secure=None)
