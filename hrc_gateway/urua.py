"""The URUA contract: what a client of a cobot gateway may rely on.

Shared by the gateway (hrc_gateway/), its backends and the driver
(hrc/cobots/drivers/opcua/). It keeps the prototype's URUA names (see
shared/reference/prototype-artefacts.md §1.2) so a client written for the
prototype works unchanged, and adds what URUA lacked: a fencing token on every
step and a message for every failed command.

Paths are relative to the cobot's root object; `node_id(cobot, path)` gives
the string node id URUA used (namespace 2, leading slash for members).

The step handshake (what the prototype's seven programs do, §4.1):
1. the client writes the step (Int24), the workspace (Int25), the poses
   (Double24–35) and the fencing token (Int26 step id, Int27 attempt), and
   sets input Bit64 — all in one write request;
2. the cobot program sees Bit64 rise, runs the step once, copies the token to
   output Int26/Int27, says what it did in output Int28 (OUTCOME_*) and sets
   output Bit64;
3. the client clears input Bit64; the program clears output Bit64.
A program that sees a token it has already run acknowledges without moving:
that is what makes a redelivered step harmless; a token older than one it has
seen for the same step id (a lower attempt) is refused the same way. Token (0, 0) means "no token"
(a prototype client) and is never deduplicated.
"""

from __future__ import annotations

import math
import re
from typing import Final

NAMESPACE_INDEX: Final = 2

# Register ranges as URUA exposed them; anything else is BadNodeIdUnknown.
BIT_REGISTERS: Final = range(64, 128)
INT_REGISTERS: Final = range(0, 48)
DOUBLE_REGISTERS: Final = range(0, 48)

INT32_MIN: Final = -(2**31)
INT32_MAX: Final = 2**31 - 1

# The step handshake registers (names as in the address space).
HANDSHAKE_BIT: Final = "Bit64"
STEP: Final = "Int24"
WORKSPACE: Final = "Int25"
FENCE_STEP: Final = "Int26"
FENCE_ATTEMPT: Final = "Int27"
POSE_REGISTERS: Final = tuple(f"Double{n}" for n in range(24, 36))  # two poses x,y,z,rx,ry,rz
# Output Int28: what the program did with the last acknowledged step.
OUTCOME: Final = "Int28"
OUTCOME_NONE: Final = 0  # no step acknowledged since the program started
OUTCOME_RAN: Final = 1  # the step ran, once
OUTCOME_DUPLICATE: Final = 2  # this token already ran: acknowledged without moving
OUTCOME_STALE: Final = 3  # a newer attempt of this step id was seen: refused without moving
OUTCOME_UNKNOWN_STEP: Final = 4  # the loaded program has no such step: nothing moved
OUTCOME_BAD_WORKSPACE: Final = 5  # the workspace is not one the program knows: nothing moved
OUTCOMES: Final = {
    OUTCOME_NONE: "none",
    OUTCOME_RAN: "ran",
    OUTCOME_DUPLICATE: "duplicate",
    OUTCOME_STALE: "stale",
    OUTCOME_UNKNOWN_STEP: "unknown step",
    OUTCOME_BAD_WORKSPACE: "bad workspace",
}

# Robot modes as URUA names them (RTDE robot_mode -1..8).
ROBOT_MODES: Final = {
    -1: "No Controller",
    0: "Disconnected",
    1: "Confirm Safety",
    2: "Booting",
    3: "Power Off",
    4: "Power On",
    5: "Idle",
    6: "Backdrive",
    7: "Running",
    8: "Updating Firmware",
}
ROBOT_MODE_RUNNING: Final = "Running"
ROBOT_MODE_IDLE: Final = "Idle"
ROBOT_MODE_POWER_OFF: Final = "Power Off"

# Safety modes as URUA names them (RTDE safety_mode 1..11).
SAFETY_MODES: Final = {
    1: "SAFETY_MODE_NORMAL",
    2: "SAFETY_MODE_REDUCED",
    3: "SAFETY_MODE_PROTECTIVE_STOP",
    4: "SAFETY_MODE_RECOVERY",
    5: "SAFETY_MODE_SAFEGUARD_STOP",
    6: "SAFETY_MODE_SYSTEM_EMERGENCY_STOP",
    7: "SAFETY_MODE_ROBOT_EMERGENCY_STOP",
    8: "SAFETY_MODE_VIOLATION",
    9: "SAFETY_MODE_FAULT",
    10: "SAFETY_MODE_VALIDATE_JOINT_ID",
    11: "SAFETY_MODE_UNDEFINED_SAFETY_MODE",
}
SAFETY_NORMAL: Final = "SAFETY_MODE_NORMAL"
SAFETY_REDUCED: Final = "SAFETY_MODE_REDUCED"
# Modes in which the robot may move under program control.
SAFETY_MODES_THAT_MOVE: Final = frozenset({SAFETY_NORMAL, SAFETY_REDUCED})

# Program states (RTDE runtime_state). URUA published nil for the transitional
# ones; we name them.
PROGRAM_STATES: Final = {
    0: "Stopping",
    1: "Stopped",
    2: "Playing",
    3: "Pausing",
    4: "Paused",
    5: "Resuming",
}
PROGRAM_PLAYING: Final = "Playing"
PROGRAM_STOPPED: Final = "Stopped"
PROGRAM_PAUSED: Final = "Paused"

# State variables the gateway publishes, with their OPC UA types (see gateway/address_space.py).
STATE_ROBOT_MODE: Final = "State/RobotMode"
STATE_SAFETY_MODE: Final = "State/SafetyMode"
STATE_PROGRAM_STATE: Final = "State/ProgramState"
STATE_CURRENT_PROGRAM: Final = "State/CurrentProgram"
STATE_LAST_ERROR: Final = "State/LastError"
# The speed slider in percent; writable, which is how a cobot is slowed rather than paused.
STATE_OVERRIDE: Final = "State/Override"
# Not in URUA: a counter the gateway bumps every HEARTBEAT_SECONDS, so a
# subscriber hears from a live gateway even when nothing else changes (and
# asyncua's client does not take a quiet subscription for a dead one).
STATE_HEARTBEAT: Final = "State/Heartbeat"
HEARTBEAT_SECONDS: Final = 0.25


class RegisterError(ValueError):
    """A register name or value a client may not use; `status` is the OPC UA status code name."""

    def __init__(self, message: str, status: str) -> None:
        super().__init__(message)
        self.status = status


_REGISTER_NAME = re.compile(r"(Bit|Int|Double)(\d{1,3})")
_KIND_FOLDERS: Final = {"Bit": "Bitregister", "Int": "Intregister", "Double": "Doubleregister"}
_KIND_RANGES: Final = {"Bit": BIT_REGISTERS, "Int": INT_REGISTERS, "Double": DOUBLE_REGISTERS}


def register_names(kind: str) -> list[str]:
    """Every register name of one kind ("Bit", "Int" or "Double"), in order."""
    return [f"{kind}{n}" for n in _KIND_RANGES[kind]]


def all_register_names() -> list[str]:
    return [name for kind in _KIND_RANGES for name in register_names(kind)]


def register_kind(name: str) -> str:
    """ "Bit", "Int" or "Double" for a register name such as "Int24"; RegisterError otherwise."""
    match = _REGISTER_NAME.fullmatch(name)
    if not match or int(match[2]) not in _KIND_RANGES[match[1]]:
        raise RegisterError(
            f"There is no register {name!r}: bits are Bit64–Bit127, ints Int0–Int47, "
            "doubles Double0–Double47.",
            "BadNodeIdUnknown",
        )
    return match[1]


def register_path(direction: str, name: str) -> str:
    """ "Register/Inputs/Intregister/Int24" for ("Inputs", "Int24")."""
    if direction not in ("Inputs", "Outputs"):
        raise ValueError(f"direction must be Inputs or Outputs, not {direction!r}")
    return f"Register/{direction}/{_KIND_FOLDERS[register_kind(name)]}/{name}"


def coerce_register_value(name: str, value: object) -> bool | int | float:
    """The value as the register holds it; RegisterError("BadTypeMismatch"/"BadOutOfRange") if it can't.

    Integers of any OPC UA width are accepted for Int and Double registers (a
    client's language may not pick Int32), but never booleans, strings or
    non-finite numbers.
    """
    kind = register_kind(name)
    if kind == "Bit":
        if isinstance(value, bool):
            return value
        raise RegisterError(f"{name} holds a Boolean, not {_type_name(value)}.", "BadTypeMismatch")
    if isinstance(value, bool) or not isinstance(value, int | float):
        expected = "an Int32" if kind == "Int" else "a Double"
        raise RegisterError(f"{name} holds {expected}, not {_type_name(value)}.", "BadTypeMismatch")
    if kind == "Int":
        if isinstance(value, float):
            raise RegisterError(f"{name} holds an Int32, not a Double.", "BadTypeMismatch")
        if not INT32_MIN <= value <= INT32_MAX:
            raise RegisterError(f"{name} holds an Int32; {value} is out of range.", "BadOutOfRange")
        return value
    if not math.isfinite(value):
        raise RegisterError(f"{name} holds a finite Double, not {value}.", "BadOutOfRange")
    return float(value)


def _type_name(value: object) -> str:
    return "a Boolean" if isinstance(value, bool) else f"a {type(value).__name__}"


def node_id(cobot: str, path: str = "") -> str:
    """URUA's string node id: "ns=2;s=cobot1" for the root, "ns=2;s=/cobot1/<path>" for members."""
    if not path:
        return f"ns={NAMESPACE_INDEX};s={cobot}"
    return f"ns={NAMESPACE_INDEX};s=/{cobot}/{path}"


def program_base_name(name: str) -> str:
    """ "pick" for "pick", "pick.urp", "/home/ur/programs/pick.urp"; ValueError for an empty name.

    SelectProgram accepts all three forms; the prototype passed full URSim paths.
    """
    base = name.strip().replace("\\", "/").rsplit("/", 1)[-1]
    if base.lower().endswith(".urp"):
        base = base[:-4]
    if not base:
        raise ValueError(f"{name!r} names no program.")
    return base
