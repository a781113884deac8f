"""A person's control of a cobot through the API, end to end on a real simulated gateway.

Each gateway starts from the simulator's boot state (powered off, no
program), as a plant's cobot does: no fixture prepares it.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from django.contrib.auth.models import User
from rest_framework.test import APIClient

from hrc.cases import jobs
from hrc.cases.choices import JobState
from hrc.cases.models import Job
from hrc.cobots.choices import CommandOutcome
from hrc.cobots.drivers.base import unreachable_message
from hrc.cobots.drivers.runner import driver_for_cobot
from hrc.cobots.models import Cobot, CobotCommand
from hrc.cobots.simulated import GatewayProcess, free_port
from hrc.organisations.models import Organisation
from hrc_gateway import urua
from tests import factories
from tests.cobots.simulator import PROGRAM, save_arm_powered_to_idle

CONFIRMED = {"confirm": True}


@pytest.fixture
def cobot(organisation: Organisation, gateway: GatewayProcess) -> Cobot:
    """cobot1 of the organisation, served by a simulated gateway in its boot state."""
    return factories.make_cobot(organisation, name="cobot1", endpoint=gateway.endpoint)


def post(client: APIClient, cobot: Cobot, action: str, body: dict[str, Any] | None = None) -> Any:
    return client.post(f"/api/cobots/{cobot.pk}/{action}/", body or {}, format="json")


def state(client: APIClient, cobot: Cobot) -> dict[str, Any]:
    response = client.get(f"/api/cobots/{cobot.pk}/state/")
    assert response.status_code == 200
    return dict(response.data)


def test_power_on_without_confirm_is_400_and_nothing_is_sent(
    engineer_client: APIClient, cobot: Cobot
) -> None:
    response = post(engineer_client, cobot, "power-on", {"confirm": False})

    assert response.status_code == 400
    assert "confirm: true" in response.data["detail"]
    assert not CobotCommand.objects.exists()
    assert state(engineer_client, cobot)["RobotMode"] == urua.ROBOT_MODE_POWER_OFF


def test_power_on_confirmed_runs_the_cobot_and_is_recorded_with_who_and_when(
    engineer_client: APIClient, engineer: User, cobot: Cobot
) -> None:
    assert state(engineer_client, cobot)["RobotMode"] == urua.ROBOT_MODE_POWER_OFF

    response = post(engineer_client, cobot, "power-on", CONFIRMED)

    assert response.status_code == 200, response.data
    assert state(engineer_client, cobot)["RobotMode"] == urua.ROBOT_MODE_RUNNING
    record = CobotCommand.objects.get()
    assert (record.command, record.outcome, record.requested_by) == (
        "power-on",
        CommandOutcome.OK,
        engineer,
    )
    assert record.finished_at is not None
    assert record.finished_at >= record.requested_at
    assert response.data["id"] == record.pk
    assert response.data["requested_by"] == engineer.username


@pytest.fixture
def idle_gateway(tmp_path: Path) -> Iterator[GatewayProcess]:
    """A gateway beside an arm a person powered on at the pendant: Idle, brakes on."""
    state_file = tmp_path / "cobot1.json"
    save_arm_powered_to_idle(state_file)
    process = GatewayProcess("cobot1", state_file).start()
    yield process
    process.stop()


def test_brake_release_takes_an_idle_cobot_to_running(
    admin_client: APIClient, organisation: Organisation, idle_gateway: GatewayProcess
) -> None:
    cobot = factories.make_cobot(organisation, name="cobot1", endpoint=idle_gateway.endpoint)
    assert state(admin_client, cobot)["RobotMode"] == urua.ROBOT_MODE_IDLE

    response = post(admin_client, cobot, "brake-release", CONFIRMED)

    assert response.status_code == 200, response.data
    assert response.data["command"] == "brake-release"
    assert state(admin_client, cobot)["RobotMode"] == urua.ROBOT_MODE_RUNNING


def test_brake_release_of_a_powered_off_cobot_is_409_in_the_gateways_words(
    engineer_client: APIClient, cobot: Cobot
) -> None:
    response = post(engineer_client, cobot, "brake-release", CONFIRMED)

    assert response.status_code == 409
    assert "Power it on first" in response.data["detail"]
    assert response.data["command"]["outcome"] == CommandOutcome.REFUSED


def test_a_program_is_loaded_started_paused_and_stopped(
    engineer_client: APIClient, cobot: Cobot
) -> None:
    assert post(engineer_client, cobot, "power-on", CONFIRMED).status_code == 200

    loaded = post(engineer_client, cobot, "program", {"program": PROGRAM, "confirm": True})
    assert loaded.status_code == 200, loaded.data
    assert loaded.data["arguments"] == {"program": PROGRAM}
    assert state(engineer_client, cobot)["CurrentProgram"] == f"/programs/{PROGRAM}.urp"
    for action, program_state in [
        ("program/start", urua.PROGRAM_PLAYING),
        ("program/pause", urua.PROGRAM_PAUSED),
        ("program/stop", urua.PROGRAM_STOPPED),
    ]:
        assert post(engineer_client, cobot, action, CONFIRMED).status_code == 200
        assert state(engineer_client, cobot)["ProgramState"] == program_state

    history = engineer_client.get(f"/api/cobots/{cobot.pk}/commands/").data
    assert [c["command"] for c in history["results"]] == [
        "stop-program",
        "pause-program",
        "start-program",
        "load-program",
        "power-on",
    ]
    assert {c["outcome"] for c in history["results"]} == {"ok"}


def test_loading_needs_a_program_and_one_the_cobot_has(
    engineer_client: APIClient, cobot: Cobot
) -> None:
    nameless = post(engineer_client, cobot, "program", CONFIRMED)
    assert nameless.status_code == 400
    assert "program" in nameless.data["detail"]

    unknown = post(engineer_client, cobot, "program", {"program": "NoSuch", "confirm": True})
    assert unknown.status_code == 400
    assert "NoSuch" in unknown.data["detail"]
    assert PROGRAM in unknown.data["detail"]  # the gateway lists the robot's programs
    assert CobotCommand.objects.get().outcome == CommandOutcome.REFUSED


def test_the_programs_are_the_gateways(engineer_client: APIClient, cobot: Cobot) -> None:
    response = engineer_client.get(f"/api/cobots/{cobot.pk}/programs/")

    assert response.status_code == 200
    assert PROGRAM in response.data
    assert len(response.data) == 7


def test_registers_are_read_all_or_by_name(engineer_client: APIClient, cobot: Cobot) -> None:
    everything = engineer_client.get(f"/api/cobots/{cobot.pk}/registers/")
    assert everything.status_code == 200
    assert list(everything.data["inputs"]) == urua.all_register_names()
    assert list(everything.data["outputs"]) == urua.all_register_names()
    assert everything.data["inputs"]["Bit64"] is False

    some = engineer_client.get(f"/api/cobots/{cobot.pk}/registers/?names=Int24,Bit64")
    assert some.status_code == 200
    assert some.data == {
        "inputs": {"Int24": 0, "Bit64": False},
        "outputs": {"Int24": 0, "Bit64": False},
    }


def test_a_name_that_is_no_register_is_400_naming_it(
    engineer_client: APIClient, cobot: Cobot
) -> None:
    response = engineer_client.get(f"/api/cobots/{cobot.pk}/registers/?names=Int24,Int99,Pos1")

    assert response.status_code == 400
    assert "Int99, Pos1" in response.data["detail"]
    assert "Int24" not in response.data["detail"].split(".")[0]


def test_a_command_is_refused_with_409_while_a_job_of_the_cobot_runs(
    engineer_client: APIClient, organisation: Organisation, engineer: User, operator: User,
    cobot: Cobot,
) -> None:  # fmt: skip
    version = factories.make_version(organisation, published_by=engineer)
    case = factories.hand_over_case(version, started_by=engineer, operator=operator, cobot=cobot)
    assert jobs.lease_next_job(cobot.pk) is not None
    assert Job.objects.get(case=case).state == JobState.RUNNING

    response = post(engineer_client, cobot, "power-on", CONFIRMED)

    assert response.status_code == 409
    assert f"case {case.pk}" in response.data["detail"]
    assert response.data["command"]["outcome"] == CommandOutcome.REFUSED
    assert CobotCommand.objects.get().message == response.data["detail"]
    assert state(engineer_client, cobot)["RobotMode"] == urua.ROBOT_MODE_POWER_OFF
    # Reading is never refused.
    assert engineer_client.get(f"/api/cobots/{cobot.pk}/registers/?names=Bit64").status_code == 200


def test_a_second_command_while_one_runs_is_refused(
    engineer_client: APIClient, admin: User, cobot: Cobot
) -> None:
    CobotCommand.objects.create(cobot=cobot, command="power-on", requested_by=admin)

    response = post(engineer_client, cobot, "power-on", CONFIRMED)

    assert response.status_code == 409
    assert f"power on that {admin.username} asked for" in response.data["detail"]
    assert state(engineer_client, cobot)["RobotMode"] == urua.ROBOT_MODE_POWER_OFF


def test_a_cobot_out_of_service_takes_no_command(engineer_client: APIClient, cobot: Cobot) -> None:
    Cobot.objects.filter(pk=cobot.pk).update(is_active=False)

    response = post(engineer_client, cobot, "power-on", CONFIRMED)

    assert response.status_code == 409
    assert "out of service" in response.data["detail"]
    assert state(engineer_client, cobot)["RobotMode"] == urua.ROBOT_MODE_POWER_OFF


def test_power_on_in_a_protective_stop_is_409_in_the_gateways_words_and_the_stop_stays(
    engineer_client: APIClient, cobot: Cobot
) -> None:
    driver_for_cobot(cobot).call("Simulator/InjectFault", "protective-stop", "")

    response = post(engineer_client, cobot, "power-on", CONFIRMED)

    assert response.status_code == 409
    assert "SAFETY_MODE_PROTECTIVE_STOP" in response.data["detail"]
    assert "teach pendant" in response.data["detail"]
    after = state(engineer_client, cobot)
    assert after["SafetyMode"] == "SAFETY_MODE_PROTECTIVE_STOP"
    assert after["RobotMode"] == urua.ROBOT_MODE_POWER_OFF
    assert CobotCommand.objects.get().outcome == CommandOutcome.REFUSED


def test_an_unreachable_cobot_is_503_recorded_as_failed(
    engineer_client: APIClient, organisation: Organisation
) -> None:
    cobot = factories.make_cobot(organisation, endpoint=f"opc.tcp://127.0.0.1:{free_port()}")

    response = post(engineer_client, cobot, "power-on", CONFIRMED)

    assert response.status_code == 503
    assert unreachable_message(cobot.name) in response.data["detail"]
    assert response.data["command"]["outcome"] == CommandOutcome.FAILED
    registers = engineer_client.get(f"/api/cobots/{cobot.pk}/registers/?names=Bit64")
    assert registers.status_code == 503
    assert state(engineer_client, cobot)["reachable"] is False


def test_an_operator_reads_state_registers_and_record_but_commands_nothing(
    operator_client: APIClient, engineer_client: APIClient, cobot: Cobot
) -> None:
    assert post(engineer_client, cobot, "power-on", CONFIRMED).status_code == 200

    assert state(operator_client, cobot)["RobotMode"] == urua.ROBOT_MODE_RUNNING
    assert operator_client.get(f"/api/cobots/{cobot.pk}/registers/").status_code == 200
    assert operator_client.get(f"/api/cobots/{cobot.pk}/commands/").data["count"] == 1
    refused = post(operator_client, cobot, "power-off", CONFIRMED)
    assert refused.status_code == 403
    assert state(operator_client, cobot)["RobotMode"] == urua.ROBOT_MODE_RUNNING
