"""The frame protocol between the gateway and hrc_step_program.script (REGISTERS.md).

ur-rtde 1.6.5 writes no bit registers and only input int/double registers
42–46 (upper range), and reads output int/double registers 36–43. URUA's step
handshake (input Bit64, Int24–27, Double24–35; output Bit64, Int24/26/27/28)
therefore travels as numbered frames on those registers:

- the gateway writes a frame's fields, then its sequence number (input int 42)
  last, so a program that sees a new number reads a complete frame;
- the program copies the frame, does what it says, and acknowledges by writing
  the frame's number to output int 36 (last, after the outcome and echoes);
- a step is three DATA frames (the twelve pose doubles, five at a time) and a
  RUN frame; the gateway waits for each acknowledgement before the next frame.

Pure Python with no ur-rtde import: the worker process, the backend and the
fake controller of the tests share it.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, Final

from hrc_gateway import urua

PROTOCOL_VERSION: Final = 1

# Input registers (gateway → program), all in ur-rtde's upper range.
IN_SEQ: Final = 42  # int: frame sequence number, written last
IN_KIND: Final = 43  # int: KIND_*
IN_ARG: Final = 44  # int: DATA offset into the pose array; RUN step
IN_WORKSPACE: Final = 45  # int: RUN workspace
IN_ATTEMPT: Final = 46  # int: RUN fencing token attempt
IN_VALUES: Final = (42, 43, 44, 45, 46)  # doubles: DATA pose values
IN_STEP_ID: Final = 42  # double: RUN fencing token step id (an exact integer)

KIND_NOOP: Final = 0  # nothing to do; acknowledged (the gateway's reset on connect)
KIND_DATA: Final = 1
KIND_RUN: Final = 2

# Output registers (program → gateway), readable by ur-rtde's upper range.
OUT_ACK: Final = 36  # int: number of the last frame consumed (RUN: once the step finished)
OUT_OUTCOME: Final = 37  # int: urua.OUTCOME_* of the last RUN
OUT_ATTEMPT: Final = 38  # int: token attempt of the last RUN
OUT_STEP: Final = 39  # int: step of the last RUN
OUT_STATUS: Final = 40  # int: STATUS_*
OUT_PROTOCOL: Final = 41  # int: PROTOCOL_VERSION, written when the program starts
OUT_STEP_ID: Final = 36  # double: token step id of the last RUN (it arrived as a double)
OUTPUT_INTS: Final = range(36, 44)  # what RTDEReceiveInterface(use_upper_range_registers) reads
OUTPUT_DOUBLES: Final = range(36, 44)

ACK_NONE: Final = -1  # the program has consumed no frame since it started
STATUS_WAITING: Final = 0
STATUS_RUNNING: Final = 1

POSE_VALUES: Final = len(urua.POSE_REGISTERS)  # 12: two poses x, y, z, rx, ry, rz
DATA_CHUNK: Final = len(IN_VALUES)
DATA_OFFSETS: Final = tuple(range(0, POSE_VALUES, DATA_CHUNK))  # 0, 5, 10

# The URUA input registers this protocol carries to the robot; anything else is refused.
CARRIED_INPUTS: Final = (
    urua.HANDSHAKE_BIT,
    urua.STEP,
    urua.WORKSPACE,
    urua.FENCE_STEP,
    urua.FENCE_ATTEMPT,
    *urua.POSE_REGISTERS,
)
CARRIED_SUMMARY: Final = "Bit64, Int24–Int27 and Double24–Double35"

NO_TOKEN: Final = (0, 0)


@dataclass(frozen=True)
class Frame:
    """One frame: the registers to write before the sequence number, in order."""

    kind: int
    ints: tuple[tuple[int, int], ...] = ()
    doubles: tuple[tuple[int, float], ...] = ()

    def to_json(self) -> dict[str, Any]:
        return {"kind": self.kind, "ints": list(self.ints), "doubles": list(self.doubles)}

    @classmethod
    def from_json(cls, data: Mapping[str, Any]) -> Frame:
        return cls(
            kind=int(data["kind"]),
            ints=tuple((int(r), int(v)) for r, v in data["ints"]),
            doubles=tuple((int(r), float(v)) for r, v in data["doubles"]),
        )


@dataclass(frozen=True)
class StepRequest:
    """One step as the client wrote it to URUA's input registers when Bit64 rose."""

    step: int
    workspace: int
    token: tuple[int, int]  # (step id, attempt); NO_TOKEN from a prototype client
    poses: tuple[float, ...]  # Double24–35

    @classmethod
    def from_inputs(cls, inputs: Mapping[str, bool | int | float]) -> StepRequest:
        return cls(
            step=int(inputs[urua.STEP]),
            workspace=int(inputs[urua.WORKSPACE]),
            token=(int(inputs[urua.FENCE_STEP]), int(inputs[urua.FENCE_ATTEMPT])),
            poses=tuple(float(inputs[name]) for name in urua.POSE_REGISTERS),
        )


@dataclass(frozen=True)
class Ack:
    """What the program wrote when it acknowledged a RUN frame."""

    seq: int
    outcome: int
    step: int
    token: tuple[int, int]

    @classmethod
    def from_outputs(cls, ints: Mapping[int, int], doubles: Mapping[int, float]) -> Ack:
        return cls(
            seq=ints[OUT_ACK],
            outcome=ints[OUT_OUTCOME],
            step=ints[OUT_STEP],
            token=(round(doubles[OUT_STEP_ID]), ints[OUT_ATTEMPT]),
        )


def step_frames(request: StepRequest) -> list[Frame]:
    """The DATA frames for the poses, then the RUN frame."""
    frames = [
        Frame(
            KIND_DATA,
            ints=((IN_ARG, offset),),
            # The last chunk is short (12 = 5 + 5 + 2): zip stops at the poses' end.
            doubles=tuple(
                zip(IN_VALUES, request.poses[offset : offset + DATA_CHUNK], strict=False)
            ),
        )
        for offset in DATA_OFFSETS
    ]
    step_id, attempt = request.token
    frames.append(
        Frame(
            KIND_RUN,
            ints=((IN_ARG, request.step), (IN_WORKSPACE, request.workspace), (IN_ATTEMPT, attempt)),
            doubles=((IN_STEP_ID, float(step_id)),),
        )
    )
    return frames


def fence_verdict(token: tuple[int, int], last: tuple[int, int] | None) -> int | None:
    """OUTCOME_DUPLICATE or OUTCOME_STALE when `token` must not be sent, judged against the
    last token the program echoed; None when it may run (always for NO_TOKEN)."""
    if token == NO_TOKEN or last is None or last == NO_TOKEN or token[0] != last[0]:
        return None
    if token[1] == last[1]:
        return urua.OUTCOME_DUPLICATE
    if token[1] < last[1]:
        return urua.OUTCOME_STALE
    return None
