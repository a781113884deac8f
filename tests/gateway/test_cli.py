"""`hrc-gateway` and `manage.py cobot_gateway` are one command: the same flags, the same refusals."""

from __future__ import annotations

import argparse
import subprocess
import sys
from pathlib import Path

import pytest

from hrc.cobots.management.commands.cobot_gateway import Command
from hrc_gateway import cli


def flags(parser: argparse.ArgumentParser) -> dict[str, object]:
    return {
        option: (action.default, action.choices, action.type)
        for action in parser._actions
        for option in action.option_strings
    }


def test_manage_py_cobot_gateway_keeps_every_flag_of_the_gateway() -> None:
    gateway = argparse.ArgumentParser()
    cli.add_arguments(gateway)
    django = Command().create_parser("manage.py", "cobot_gateway")

    assert set(flags(gateway)) >= {"--name", "--port", "--host", "--backend", "--robot",
                                   "--program", "--time-scale", "--seed", "--state-file",
                                   "--pki", "--insecure"}  # fmt: skip
    assert flags(gateway).items() <= flags(django).items()


def test_the_gateway_refuses_insecure_off_loopback_without_a_traceback(tmp_path: Path) -> None:
    result = subprocess.run(
        [sys.executable, "-m", "hrc_gateway", "--name", "cobot1", "--insecure", "--host", "0.0.0.0",
         "--state-file", str(tmp_path / "cobot1.json")],
        cwd=Path(cli.__file__).parents[1], capture_output=True, text=True, timeout=60, check=False,
    )  # fmt: skip

    assert result.returncode == 1
    assert "hrc-gateway: error: --insecure serves cobot1" in result.stderr
    assert "loopback only" in result.stderr
    assert "Traceback" not in result.stderr


def test_the_ur_backend_needs_a_robot(tmp_path: Path) -> None:
    parser = argparse.ArgumentParser()
    cli.add_arguments(parser)
    options = vars(parser.parse_args(["--name", "cobot1", "--backend", "ur-rtde", "--insecure"]))
    defaults = cli.Defaults(pki_dir=tmp_path / "pki", sim_state_dir=tmp_path / "cobots")

    with pytest.raises(cli.StartError, match="--backend ur-rtde needs --robot HOST"):
        cli.serve(options, defaults, print)
