"""The cobot commands a person runs from a shell, against a real simulated gateway."""

from __future__ import annotations

from io import StringIO
from pathlib import Path

import pytest
from django.core.management import CommandError, call_command

from hrc.cobots.drivers.opcua.driver import OpcUaDriver
from hrc.cobots.simulated import GatewayProcess, free_port
from hrc.organisations.models import Organisation
from tests import factories


def run(*arguments: str) -> str:
    out = StringIO()
    call_command(*arguments, stdout=out)
    return out.getvalue()


# The `driver` fixture powers the cobot on and starts its program before each test.


def test_cobot_step_runs_a_step_and_says_what_happened(
    gateway: GatewayProcess, driver: OpcUaDriver
) -> None:
    output = run(
        "cobot_step", "cobot1", "--endpoint", gateway.endpoint,
        "--step", "2", "--workspace", "0", "--pose", "0.05", "0.05", "0.1", "0", "0", "0",
        "--fence", "41.1",
    )  # fmt: skip
    assert "step 2 sent; outcome: ran" in output
    again = run(
        "cobot_step", "cobot1", "--endpoint", gateway.endpoint, "--step", "2", "--fence", "41.1"
    )
    assert "not sent again (it had already run)" in again


def test_cobot_step_reports_a_protective_stop_clearly(
    gateway: GatewayProcess, driver: OpcUaDriver
) -> None:
    run("cobot_fault", "cobot1", "--endpoint", gateway.endpoint, "protective-stop")
    with pytest.raises(CommandError, match=r"protective stop.*a person must check the cell"):
        run("cobot_step", "cobot1", "--endpoint", gateway.endpoint, "--step", "1")


def test_cobot_step_reports_a_dead_gateway_without_hanging() -> None:
    endpoint = f"opc.tcp://127.0.0.1:{free_port()}"
    with pytest.raises(
        CommandError, match=r"Cannot reach cobot cobot1 at its endpoint.*a retry may help"
    ):
        run(
            "cobot_step",
            "cobot1",
            "--endpoint",
            endpoint,
            "--step",
            "1",
            "--connect-timeout",
            "1",
            "--timeout",
            "2",
        )


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        (["--step", "1", "--fence", "x.y"], "--fence takes ID.ATTEMPT"),
        (["--step", str(2**40)], "out of range"),
        (["--step", "1", "--endpoint", "http://x"], "opc.tcp"),
    ],
)
def test_cobot_step_refuses_bad_arguments(arguments: list[str], message: str) -> None:
    with pytest.raises(CommandError, match=message):
        run("cobot_step", "cobot1", *arguments)


def test_cobot_step_finds_a_registered_cobot(
    gateway: GatewayProcess, driver: OpcUaDriver, organisation: Organisation
) -> None:
    factories.make_cobot(organisation, name="cobot1", endpoint=gateway.endpoint)
    assert "outcome: ran" in run("cobot_step", "cobot1", "--step", "1", "--fence", "42.1")
    with pytest.raises(CommandError, match="No registered cobot is named 'cobot7'"):
        run("cobot_step", "cobot7", "--step", "1")


def test_cobot_call_reads_and_wrong_methods_are_named(
    gateway: GatewayProcess, driver: OpcUaDriver
) -> None:
    output = run("cobot_call", "cobot1", "--endpoint", gateway.endpoint, "PauseProgram")
    assert "ProgramState: Paused" in output
    with pytest.raises(CommandError, match="no node 'Launch'"):
        run("cobot_call", "cobot1", "--endpoint", gateway.endpoint, "Launch")


@pytest.mark.parametrize("host", ["a:b", "::ffff:127.0.0.1:80", "[::ffff:127.0.0.1"])
def test_cobot_gateway_names_a_host_that_is_no_host_without_a_traceback(host: str) -> None:
    with pytest.raises(CommandError, match=r"--host: .* is neither a host name nor an IP address"):
        run("cobot_gateway", "--name", "cobot1", "--insecure", "--host", host)


def test_cobot_gateway_refuses_insecure_off_loopback(tmp_path: Path) -> None:
    with pytest.raises(CommandError, match="loopback only"):
        run("cobot_gateway", "--name", "cobot1", "--insecure", "--host", "0.0.0.0")
