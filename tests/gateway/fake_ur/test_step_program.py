"""The fake controller's step program, driven register by register as the gateway would.

It must do what hrc_step_program.script does, or the gateway's tests prove
nothing about the robot; these tests pin the script's rules down.
"""

from __future__ import annotations

from hrc_gateway import urua
from hrc_gateway.ur import protocol
from hrc_gateway.ur.protocol import Frame, StepRequest
from tests.gateway.fake_ur.controller import PAUSED, FakeController

CYCLE = 0.002


def ready_controller() -> FakeController:
    controller = FakeController(step_duration=0.01)
    controller.make_ready()
    return controller


class Gateway:
    """Writes frames the way rtde_worker does and runs the controller until each is acknowledged."""

    def __init__(self, controller: FakeController) -> None:
        self.controller = controller
        self.seq = 0

    def write(self, frame: Frame) -> int:
        self.seq += 1
        values: dict[str, bool | int | float] = {"input_int_register_43": frame.kind}
        values |= {f"input_int_register_{r}": v for r, v in frame.ints}
        values |= {f"input_double_register_{r}": v for r, v in frame.doubles}
        self.controller.apply_inputs(values)
        self.controller.apply_inputs({"input_int_register_42": self.seq})
        return self.seq

    def send(self, request: StepRequest, cycles: int = 100) -> tuple[int, int, int, int]:
        """(outcome, step, token step id, attempt) once the RUN frame is acknowledged."""
        for frame in protocol.step_frames(request):
            seq = self.write(frame)
            for _ in range(cycles):
                self.controller.tick(CYCLE)
                if self.controller.out_ints[protocol.OUT_ACK] == seq:
                    break
            else:
                raise AssertionError(f"frame {seq} was not acknowledged")
        ints, doubles = self.controller.out_ints, self.controller.out_doubles
        return (
            ints[protocol.OUT_OUTCOME],
            ints[protocol.OUT_STEP],
            round(doubles[protocol.OUT_STEP_ID]),
            ints[protocol.OUT_ATTEMPT],
        )


def request(step: int = 2, workspace: int = 1, token: tuple[int, int] = (7, 1)) -> StepRequest:
    return StepRequest(step, workspace, token, tuple(float(i) / 10 for i in range(12)))


def test_a_step_runs_once_with_all_twelve_pose_values_and_echoes_its_token() -> None:
    controller = ready_controller()

    outcome = Gateway(controller).send(request())

    assert outcome == (urua.OUTCOME_RAN, 2, 7, 1)
    [execution] = controller.executions
    assert execution.poses == tuple(float(i) / 10 for i in range(12))
    assert execution.workspace == 1


def test_a_token_that_ran_is_a_duplicate_and_a_lower_attempt_is_stale() -> None:
    controller = ready_controller()
    gateway = Gateway(controller)
    gateway.send(request(token=(7, 2)))

    assert gateway.send(request(token=(7, 2)))[0] == urua.OUTCOME_DUPLICATE
    assert gateway.send(request(token=(7, 1)))[0] == urua.OUTCOME_STALE
    assert gateway.send(request(token=(7, 3)))[0] == urua.OUTCOME_RAN
    assert controller.ran() == 2


def test_steps_without_a_token_always_run() -> None:
    controller = ready_controller()
    gateway = Gateway(controller)

    for _ in range(2):
        assert gateway.send(request(token=(0, 0)))[0] == urua.OUTCOME_RAN
    assert controller.ran() == 2


def test_the_program_remembers_sixteen_step_ids_round_robin() -> None:
    controller = ready_controller()
    gateway = Gateway(controller)
    for step_id in range(1, 18):  # the 17th overwrites the slot of the 1st
        gateway.send(request(token=(step_id, 1)))

    assert gateway.send(request(token=(2, 1)))[0] == urua.OUTCOME_DUPLICATE
    assert gateway.send(request(token=(1, 1)))[0] == urua.OUTCOME_RAN


def test_unknown_steps_and_workspaces_are_refused_without_moving() -> None:
    controller = ready_controller()
    gateway = Gateway(controller)

    assert gateway.send(request(step=99))[0] == urua.OUTCOME_UNKNOWN_STEP
    assert gateway.send(request(workspace=42, token=(8, 1)))[0] == urua.OUTCOME_BAD_WORKSPACE
    assert controller.ran() == 0


def test_a_frame_written_before_the_program_started_is_not_run() -> None:
    controller = FakeController()
    gateway = Gateway(controller)
    for frame in protocol.step_frames(request()):
        gateway.write(frame)

    controller.make_ready()
    for _ in range(50):
        controller.tick(CYCLE)

    assert controller.ran() == 0
    assert controller.out_ints[protocol.OUT_ACK] == protocol.ACK_NONE
    assert controller.out_ints[protocol.OUT_PROTOCOL] == protocol.PROTOCOL_VERSION


def test_a_protective_stop_suspends_a_step_until_the_program_resumes() -> None:
    controller = ready_controller()
    controller.step_duration = 0.02
    gateway = Gateway(controller)
    for frame in protocol.step_frames(request()):
        gateway.write(frame)
        controller.tick(CYCLE)
    controller.protective_stop()
    for _ in range(50):
        controller.tick(CYCLE)
    assert controller.runtime_state == PAUSED
    assert controller.ran() == 0

    controller.clear_protective_stop()
    assert controller.play()
    for _ in range(50):
        controller.tick(CYCLE)

    assert controller.ran() == 1
    assert controller.out_ints[protocol.OUT_ACK] == gateway.seq
