"""The fake's servers speak what ur-rtde expects: RTDE v2 framing and ownership, dashboard lines.

A plain-socket RTDE client is used here on purpose: ur-rtde's RTDE
constructors hold the GIL while they wait for the network, so in this process
they would wait for a fake that cannot run (see rtde_worker.py).
"""

from __future__ import annotations

import socket
import struct
import time

from tests.gateway.fake_ur import HOST, RTDE_PORT, FakeUR, wire
from tests.gateway.fake_ur.dashboard_server import GREETING
from tests.support.polling import until


class RawRTDE:
    def __init__(self) -> None:
        self.sock = socket.create_connection((HOST, RTDE_PORT), timeout=2.0)
        self.buffer = b""

    def send(self, kind: int, payload: bytes = b"") -> None:
        self.sock.sendall(wire.packet(kind, payload))

    def receive(self) -> tuple[int, bytes]:
        while len(self.buffer) < wire.HEADER.size or len(self.buffer) < self._size():
            chunk = self.sock.recv(65536)
            if not chunk:
                raise ConnectionError("closed")
            self.buffer += chunk
        size = self._size()
        packet, self.buffer = self.buffer[:size], self.buffer[size:]
        return packet[2], packet[wire.HEADER.size :]

    def _size(self) -> int:
        return int(wire.HEADER.unpack(self.buffer[: wire.HEADER.size])[0])

    def setup_inputs(self, *names: str) -> tuple[int, list[str]]:
        self.send(wire.CONTROL_PACKAGE_SETUP_INPUTS, ",".join(names).encode())
        kind, payload = self.receive()
        assert kind == wire.CONTROL_PACKAGE_SETUP_INPUTS
        return payload[0], payload[1:].decode().split(",")

    def setup_outputs(self, frequency: float, *names: str) -> tuple[int, list[str]]:
        self.send(
            wire.CONTROL_PACKAGE_SETUP_OUTPUTS,
            struct.pack(">d", frequency) + ",".join(names).encode(),
        )
        kind, payload = self.receive()
        assert kind == wire.CONTROL_PACKAGE_SETUP_OUTPUTS
        return payload[0], payload[1:].decode().split(",")

    def close(self) -> None:
        self.sock.close()


def test_protocol_v2_is_accepted_and_recipes_are_numbered_from_one(fake_ur: FakeUR) -> None:
    client = RawRTDE()
    client.send(wire.REQUEST_PROTOCOL_VERSION, struct.pack(">H", 2))
    assert client.receive() == (wire.REQUEST_PROTOCOL_VERSION, b"\x01")

    assert client.setup_inputs("input_int_register_47", "input_int_register_42") == (
        1,
        ["INT32", "INT32"],
    )
    assert client.setup_inputs("speed_slider_mask", "speed_slider_fraction") == (
        2,
        ["UINT32", "DOUBLE"],
    )
    assert client.setup_outputs(125.0, "robot_mode", "no_such_field") == (0, ["INT32", "NOT_FOUND"])
    client.close()


def test_an_input_owned_by_one_connection_is_in_use_for_others_until_it_closes(
    fake_ur: FakeUR,
) -> None:
    owner, other = RawRTDE(), RawRTDE()
    assert owner.setup_inputs("input_int_register_42")[0] == 1

    assert other.setup_inputs("input_int_register_42", "input_int_register_43") == (
        0,
        ["IN_USE", "INT32"],
    )
    owner.close()
    until(
        lambda: other.setup_inputs("input_int_register_42")[0] != 0,
        timeout=2,
        interval=0.01,
        message="the closed connection kept the register",
    )
    other.close()


def test_inputs_a_fieldbus_adapter_owns_are_in_use(fake_ur: FakeUR) -> None:
    fake_ur.rtde.external_owners.add("input_double_register_44")
    client = RawRTDE()

    assert client.setup_inputs("input_double_register_44")[1] == ["IN_USE"]
    client.close()


def test_input_packages_reach_the_controller_and_outputs_stream_after_start(
    fake_ur: FakeUR,
) -> None:
    client = RawRTDE()
    recipe, _ = client.setup_inputs("input_int_register_47", "input_int_register_42")
    client.send(wire.DATA_PACKAGE, bytes([recipe]) + struct.pack(">ii", 49, 1234))
    fake_ur.wait_until(lambda c: c.input_int(42) == 1234)
    output, _ = client.setup_outputs(100.0, "output_int_register_36", "actual_q")
    fake_ur.controller.out_ints[36] = 77

    client.send(wire.CONTROL_PACKAGE_START)
    assert client.receive() == (wire.CONTROL_PACKAGE_START, b"\x01")
    started = time.monotonic()
    packages = []
    while time.monotonic() - started < 0.3:
        packages.append(client.receive())

    assert 20 <= len(packages) <= 40  # 100 Hz for 0.3 s
    kind, payload = packages[-1]
    assert kind == wire.DATA_PACKAGE
    assert payload[0] == output
    assert struct.unpack(">i6d", payload[1:])[0] == 77
    client.close()


def test_the_dashboard_greets_and_answers_one_line_per_command(fake_ur: FakeUR) -> None:
    with socket.create_connection((HOST, fake_ur.dashboard_port), timeout=2.0) as sock:
        lines = sock.makefile("rw", newline="\n")

        def ask(command: str) -> str:
            lines.write(command + "\n")
            lines.flush()
            return lines.readline().strip()

        assert lines.readline().strip() == GREETING
        assert ask("load missing.urp") == "File not found: missing.urp"
        assert ask("load hrc_steps.urp") == "Loading program: hrc_steps.urp"
        assert ask("get loaded program") == "Loaded program: /programs/hrc_steps.urp"
        assert ask("robotmode") == "Robotmode: POWER_OFF"
        assert ask("play") == "Failed to execute: play"
        assert ask("is in remote control") == "true"
        fake_ur.controller.remote_control = False
        assert ask("power on").startswith("Command is not allowed")
