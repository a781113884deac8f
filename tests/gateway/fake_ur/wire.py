"""RTDE wire protocol v2 as UR documents it: packets, types, and which fields exist.

A packet is a big-endian header (uint16 size including the header, uint8
type) and a payload. The type table names what the controller packs for each
field; ur-rtde decodes by its own table, so these must agree with it
(robot_state.cpp: vectors of 6 doubles except the accelerometer, payload_cog
and the elbow, which have 3).
"""

from __future__ import annotations

import asyncio
import re
import struct
from collections.abc import Sequence
from typing import Any, Final

HEADER: Final = struct.Struct(">HB")

REQUEST_PROTOCOL_VERSION: Final = ord("V")
GET_URCONTROL_VERSION: Final = ord("v")
TEXT_MESSAGE: Final = ord("M")
DATA_PACKAGE: Final = ord("U")
CONTROL_PACKAGE_SETUP_OUTPUTS: Final = ord("O")
CONTROL_PACKAGE_SETUP_INPUTS: Final = ord("I")
CONTROL_PACKAGE_START: Final = ord("S")
CONTROL_PACKAGE_PAUSE: Final = ord("P")

FORMATS: Final = {
    "BOOL": "?",
    "UINT8": "B",
    "UINT32": "I",
    "UINT64": "Q",
    "INT32": "i",
    "DOUBLE": "d",
    "VECTOR3D": "3d",
    "VECTOR6D": "6d",
    "VECTOR6INT32": "6i",
    "VECTOR6UINT32": "6I",
}

_V6D = "VECTOR6D"
OUTPUTS: Final = {
    "timestamp": "DOUBLE",
    **dict.fromkeys(
        [
            "target_q",
            "target_qd",
            "target_qdd",
            "target_current",
            "target_moment",
            "actual_q",
            "actual_qd",
            "actual_qdd",
            "actual_current",
            "actual_moment",
            "joint_control_output",
            "actual_TCP_pose",
            "actual_TCP_speed",
            "actual_TCP_force",
            "target_TCP_pose",
            "target_TCP_speed",
            "joint_temperatures",
            "actual_joint_voltage",
            "ft_raw_wrench",
            "payload_inertia",
        ],
        _V6D,
    ),
    "actual_digital_input_bits": "UINT64",
    "actual_digital_output_bits": "UINT64",
    "actual_execution_time": "DOUBLE",
    "robot_mode": "INT32",
    "joint_mode": "VECTOR6INT32",
    "safety_mode": "INT32",
    "safety_status": "INT32",
    "actual_tool_accelerometer": "VECTOR3D",
    "speed_scaling": "DOUBLE",
    "target_speed_fraction": "DOUBLE",
    "actual_momentum": "DOUBLE",
    "actual_main_voltage": "DOUBLE",
    "actual_robot_voltage": "DOUBLE",
    "actual_robot_current": "DOUBLE",
    "runtime_state": "UINT32",
    "robot_status_bits": "UINT32",
    "safety_status_bits": "UINT32",
    "standard_analog_input0": "DOUBLE",
    "standard_analog_input1": "DOUBLE",
    "standard_analog_output0": "DOUBLE",
    "standard_analog_output1": "DOUBLE",
    "payload": "DOUBLE",
    "payload_cog": "VECTOR3D",
    "output_bit_registers0_to_31": "UINT32",
    "output_bit_registers32_to_63": "UINT32",
    "input_bit_registers0_to_31": "UINT32",
    "input_bit_registers32_to_63": "UINT32",
    "speed_slider_mask": "UINT32",
}

INPUTS: Final = {
    "speed_slider_mask": "UINT32",
    "speed_slider_fraction": "DOUBLE",
    "standard_digital_output_mask": "UINT8",
    "standard_digital_output": "UINT8",
    "configurable_digital_output_mask": "UINT8",
    "configurable_digital_output": "UINT8",
    "tool_digital_output_mask": "UINT8",
    "tool_digital_output": "UINT8",
    "standard_analog_output_mask": "UINT8",
    "standard_analog_output_type": "UINT8",
    "standard_analog_output_0": "DOUBLE",
    "standard_analog_output_1": "DOUBLE",
    "input_bit_registers0_to_31": "UINT32",
    "input_bit_registers32_to_63": "UINT32",
}

_REGISTER = re.compile(r"(input|output)_(bit|int|double)_register_(\d+)")
_REGISTER_TYPES: Final = {"bit": "BOOL", "int": "INT32", "double": "DOUBLE"}
_REGISTER_RANGES: Final = {"bit": range(64, 128), "int": range(48), "double": range(48)}


def register_type(name: str) -> str | None:
    """The type of a general purpose register field (inputs are readable as outputs too)."""
    match = _REGISTER.fullmatch(name)
    if match is None or int(match[3]) not in _REGISTER_RANGES[match[2]]:
        return None
    return _REGISTER_TYPES[match[2]]


def output_type(name: str) -> str | None:
    return OUTPUTS.get(name) or register_type(name)


def input_type(name: str) -> str | None:
    match = _REGISTER.fullmatch(name)
    if match is not None and match[1] == "output":
        return None
    return INPUTS.get(name) or register_type(name)


def recipe_struct(types: Sequence[str]) -> struct.Struct:
    return struct.Struct(">" + "".join(FORMATS[t] for t in types))


def flatten(types: Sequence[str], values: Sequence[Any]) -> list[Any]:
    """Values in struct order: vectors spread out."""
    flat: list[Any] = []
    for kind, value in zip(types, values, strict=True):
        if kind.startswith("VECTOR"):
            flat.extend(value)
        else:
            flat.append(value)
    return flat


def unflatten(types: Sequence[str], flat: Sequence[Any]) -> list[Any]:
    values: list[Any] = []
    i = 0
    for kind in types:
        size = int(FORMATS[kind][0]) if FORMATS[kind][0].isdigit() else 1
        values.append(list(flat[i : i + size]) if size > 1 else flat[i])
        i += size
    return values


def packet(kind: int, payload: bytes = b"") -> bytes:
    return HEADER.pack(HEADER.size + len(payload), kind) + payload


async def read_packet(reader: asyncio.StreamReader) -> tuple[int, bytes]:
    """One packet; asyncio.IncompleteReadError when the peer closed the connection."""
    size, kind = HEADER.unpack(await reader.readexactly(HEADER.size))
    return kind, await reader.readexactly(size - HEADER.size)
