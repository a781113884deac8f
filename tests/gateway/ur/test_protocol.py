"""The frame protocol's pure parts: how a step becomes frames, and the gateway's fencing rule."""

from __future__ import annotations

from hrc_gateway import urua
from hrc_gateway.ur import protocol
from hrc_gateway.ur.protocol import StepRequest


def test_a_step_is_three_data_frames_covering_the_twelve_pose_values_then_a_run_frame() -> None:
    request = StepRequest(4, 2, (123456789, 3), tuple(float(n) for n in range(12)))

    *data, run = protocol.step_frames(request)

    assert [frame.kind for frame in data] == [protocol.KIND_DATA] * 3
    carried = [value for frame in data for _, value in frame.doubles]
    assert carried == [float(n) for n in range(12)]
    assert [dict(frame.ints)[protocol.IN_ARG] for frame in data] == [0, 5, 10]
    assert run.kind == protocol.KIND_RUN
    assert dict(run.ints) == {protocol.IN_ARG: 4, protocol.IN_WORKSPACE: 2, protocol.IN_ATTEMPT: 3}
    assert dict(run.doubles) == {protocol.IN_STEP_ID: 123456789.0}


def test_frames_survive_the_json_line_to_the_worker() -> None:
    for frame in protocol.step_frames(StepRequest(1, 0, (5, 1), (0.25,) * 12)):
        assert protocol.Frame.from_json(frame.to_json()) == frame


def test_the_gateway_fences_against_the_last_echoed_token_only() -> None:
    last = (17, 2)

    assert protocol.fence_verdict((17, 2), last) == urua.OUTCOME_DUPLICATE
    assert protocol.fence_verdict((17, 1), last) == urua.OUTCOME_STALE
    assert protocol.fence_verdict((17, 3), last) is None
    assert protocol.fence_verdict((16, 1), last) is None  # left to the program
    assert protocol.fence_verdict((0, 0), (0, 0)) is None
    assert protocol.fence_verdict((17, 2), None) is None


def test_carried_inputs_are_the_handshake_registers() -> None:
    assert set(protocol.CARRIED_INPUTS) == {
        "Bit64",
        "Int24",
        "Int25",
        "Int26",
        "Int27",
        *urua.POSE_REGISTERS,
    }
