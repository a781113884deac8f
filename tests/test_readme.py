"""Every command in the README's and the docs' code blocks works as written on a fresh clone.

The commands are read from the fenced command blocks (no language, or bash/sh/shell/console)
of README.md, docker/README.md and docs/*.md (comments after `#` dropped, `\\` continuations
joined); blocks marked text, json or python are not commands. Each must be named below,
either with how this test runs it or with why it cannot run here, so a command added without
a test fails `test_every_readme_command_is_run_or_has_a_reason`. They run on the embedded
default (no DATABASE_URL, no REDIS_URL) with the clone's files under a scratch
HRC_VAR_DIR, HRC_PKI_DIR and HRC_SIM_STATE_DIR. Changes to a command as written: a free
port instead of 4841 (tests run side by side), and the placeholder my-pattern.json is an
example file copied to the scratch folder.
"""

from __future__ import annotations

import json
import re
import shutil
import socket
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from hrc.cobots.simulated import free_port
from tests.cases.test_run_pattern_embedded import ROOT, embedded_environment

FENCE = re.compile(r"^```([^\n]*)\n(.*?)^```", re.MULTILINE | re.DOTALL)
# The info strings of a block of commands; any other language is an example, not a command.
COMMAND_BLOCKS = frozenset({"", "bash", "sh", "shell", "console"})

# The commands this module cannot run, and why.
CANNOT_RUN = {
    "make demo": "serves until stopped; the demo's browser test (tests/browser) runs it",
    "make test": "this suite is what it runs",
    ".venv/bin/python manage.py cobot_gateway --name cobot1 --port 4841 --backend ur-rtde "
    "--robot 192.168.0.210 --program hrc_steps": "needs a UR controller at 192.168.0.210",
    ".venv/bin/celery -A hrc worker --beat --loglevel INFO": (
        "needs Redis as the broker; tests/cases/test_workers.py starts this worker "
        "(tests.support.workers.WorkerProcess) against a private Redis"
    ),
    "cd docker": "docker: no engine here",
    "cp /dev/null .env && chmod 600 .env": "docker: the compose file's .env, in docker/",
    "docker compose up -d --build": "docker: no engine here",
    "docker compose ps": "docker: no engine here",
    "docker compose run --rm web python manage.py createsuperuser": (
        "docker: no engine here (and interactive)"
    ),
}
# Run by this module: in test_the_readme_commands_work_on_a_fresh_clone, or for the
# docker one, its command inside the container run here as
# test_the_docker_load_demo_arguments_register_the_gateways.
RUN_HERE = {
    ".venv/bin/python manage.py check_pattern hrc/patterns/examples/*.json",
    ".venv/bin/python manage.py check_pattern --json my-pattern.json",
    ".venv/bin/python manage.py predict hrc/patterns/examples/use_cases/1_spot_taping.json "
    "--cases 200 --people o=2",
    ".venv/bin/python manage.py predict --json --cases 100 my-pattern.json",
    ".venv/bin/python manage.py cobot_certificates cobot1 --user hrc "
    "--password-env COBOT1_PASSWORD",
    ".venv/bin/python manage.py cobot_gateway --name cobot1 --port 4841 --backend sim",
    ".venv/bin/python manage.py cobot_gateway --name cobot1 --port 4841 --insecure "
    "--time-scale 0.05",
    ".venv/bin/python manage.py cobot_call cobot1 PowerOn",
    ".venv/bin/python manage.py cobot_call cobot1 SelectProgram Coexistence_PickAndPlace",
    ".venv/bin/python manage.py cobot_call cobot1 StartProgram",
    ".venv/bin/python manage.py cobot_step cobot1 --step 2 --workspace 0 --pose 0.1 0.2 0.05 0 0 0",
    ".venv/bin/python manage.py cobot_fault cobot1 protective-stop",
    ".venv/bin/python manage.py run_pattern hrc/patterns/examples/coop_1o1c_polishing.json "
    "--simulate --cases 3 --time-scale 0.05 --json",
    ".venv/bin/python manage.py live_cobots",
    "docker compose run --rm web python manage.py load_demo --cobot-endpoint "
    "'opc.tcp://gateway-{cobot}:4840'",
    *(
        f"docker compose run --rm -e COBOT{n}_GATEWAY_PASSWORD web python manage.py cobot_secret "
        f"cobot{n} --organisation demo-plant --user hrc --password-env COBOT{n}_GATEWAY_PASSWORD "
        f"--cobot cobot{n}"
        for n in (1, 2)
    ),
}


def readme_commands(path: Path) -> list[str]:
    """The commands of a Markdown file's fenced blocks, one per line, without comments."""
    commands = []
    for language, block in FENCE.findall(path.read_text()):
        if language.strip() not in COMMAND_BLOCKS:
            continue
        for line in block.replace("\\\n", " ").splitlines():
            command = " ".join(re.sub(r"\s#.*$", "", line).split())
            if command and not command.startswith("#"):
                commands.append(command)
    return commands


def documented_files() -> list[Path]:
    """The Markdown files whose commands a reader runs: the READMEs and the docs' pages."""
    return [
        ROOT / "README.md",
        ROOT / "docker" / "README.md",
        *sorted((ROOT / "docs").glob("*.md")),
    ]


def all_commands() -> list[str]:
    return [command for path in documented_files() for command in readme_commands(path)]


def test_every_readme_command_is_run_or_has_a_reason() -> None:
    commands = all_commands()

    untested = [c for c in commands if c not in RUN_HERE and c not in CANNOT_RUN]
    assert untested == [], "README commands with neither a test nor a reason"
    assert set(RUN_HERE) | set(CANNOT_RUN) <= set(commands), "stale entries"


def test_the_fence_parser_reads_commands_and_drops_comments(tmp_path: Path) -> None:
    readme = tmp_path / "README.md"
    readme.write_text(
        "text `not this`\n\n```\nmake a   # why\n# only a comment\n\nrun \\\n    --x 1\n```\n"
    )

    assert readme_commands(readme) == ["make a", "run --x 1"]


def test_only_command_blocks_hold_commands(tmp_path: Path) -> None:
    page = tmp_path / "page.md"
    page.write_text("```bash\nmake a\n```\n\n```text\nnot/a/command\n```\n\n```json\n{}\n```\n")

    assert readme_commands(page) == ["make a"]


def test_the_docs_pages_are_read_for_commands() -> None:
    assert ROOT / "docs" / "admins.md" in documented_files()
    assert ".venv/bin/python manage.py cobot_call cobot1 PowerOn" in readme_commands(
        ROOT / "docs" / "admins.md"
    )


class Clone:
    """A fresh clone's state in a scratch folder, and the README's commands run against it."""

    def __init__(self, scratch: Path) -> None:
        self.scratch = scratch
        self.environment = embedded_environment(scratch)
        self.environment["COBOT1_PASSWORD"] = "a-password-for-this-test"
        self.servers: list[subprocess.Popen[str]] = []

    def run(
        self, written: str, *, replace: dict[str, str] | None = None, timeout: float = 120
    ) -> subprocess.CompletedProcess[str]:
        """Runs the README's command `written`, with only the `replace` substitutions."""
        command = self.command(written, replace)
        result = subprocess.run(
            ["bash", "-c", command], cwd=ROOT, env=self.environment,
            capture_output=True, text=True, timeout=timeout,
        )  # fmt: skip
        assert result.returncode == 0, f"{command}\n{result.stdout[-2000:]}{result.stderr[-3000:]}"
        assert "Traceback" not in result.stderr, result.stderr
        return result

    def serve(self, written: str, port: int) -> subprocess.Popen[str]:
        """Starts the README's server command `written` on `port` instead of 4841."""
        return self.serve_unported(written, {"--port 4841": f"--port {port}"})

    def serve_unported(
        self, written: str, replace: dict[str, str] | None = None
    ) -> subprocess.Popen[str]:
        """Starts the README's long-running command `written`; stopped with the clone."""
        command = self.command(written, replace)
        server = subprocess.Popen(
            ["bash", "-c", f"exec {command}"], cwd=ROOT, env=self.environment,
            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
        )  # fmt: skip
        self.servers.append(server)
        return server

    @staticmethod
    def command(written: str, replace: dict[str, str] | None) -> str:
        assert written in RUN_HERE, written
        command = written
        for old, new in (replace or {}).items():
            assert old in command, old
            command = command.replace(old, new)
        return command

    def stop(self) -> None:
        for server in self.servers:
            server.terminate()
            try:
                server.wait(timeout=10)
            except subprocess.TimeoutExpired:
                server.kill()
                server.wait()
            if server.stdout:
                server.stdout.close()


@pytest.fixture
def clone(tmp_path: Path) -> Iterator[Clone]:
    state = Clone(tmp_path)
    yield state
    state.stop()


def wait_for_port(port: int, server: subprocess.Popen[str], timeout: float = 30) -> None:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        assert server.poll() is None, server.stdout.read() if server.stdout else ""
        with socket.socket() as probe:
            if probe.connect_ex(("127.0.0.1", port)) == 0:
                return
        time.sleep(0.1)
    raise AssertionError(f"nothing listens on {port} after {timeout} s")


def test_the_readme_commands_work_on_a_fresh_clone(clone: Clone) -> None:
    checked = clone.run(".venv/bin/python manage.py check_pattern hrc/patterns/examples/*.json")
    examples = sorted((ROOT / "hrc" / "patterns" / "examples").glob("*.json"))
    assert len(checked.stdout.splitlines()) == len(examples)
    assert all(": valid" in line for line in checked.stdout.splitlines())
    mine = clone.scratch / "my-pattern.json"
    shutil.copy(examples[0], mine)
    checked = clone.run(
        ".venv/bin/python manage.py check_pattern --json my-pattern.json",
        replace={"my-pattern.json": str(mine)},
    )
    assert json.loads(checked.stdout)["valid"] is True
    predicted = clone.run(
        ".venv/bin/python manage.py predict hrc/patterns/examples/use_cases/1_spot_taping.json "
        "--cases 200 --people o=2"
    )
    assert "200 of 200 cases completed" in predicted.stdout
    predicted = clone.run(
        ".venv/bin/python manage.py predict --json --cases 100 my-pattern.json",
        replace={"my-pattern.json": str(mine)},
    )
    assert json.loads(predicted.stdout)["prediction"]["completed"] == 100

    # On a fresh clone run_pattern creates and migrates the embedded database itself.
    assert not (clone.scratch / "var" / "hrc.sqlite3").exists()
    ran = clone.run(
        ".venv/bin/python manage.py run_pattern hrc/patterns/examples/coop_1o1c_polishing.json "
        "--simulate --cases 3 --time-scale 0.05 --json"
    )
    assert ran.stdout.count('"event": "case-completed"') == 3

    clone.run(
        ".venv/bin/python manage.py cobot_certificates cobot1 --user hrc "
        "--password-env COBOT1_PASSWORD"
    )
    assert (clone.scratch / "pki" / "gateways" / "cobot1" / "users.json").exists()
    secured_port = free_port()
    secured = clone.serve(
        ".venv/bin/python manage.py cobot_gateway --name cobot1 --port 4841 --backend sim",
        secured_port,
    )
    wait_for_port(secured_port, secured)

    # The cobot commands name a registered cobot: what `make demo` registers (load_demo),
    # here with cobot1 pointing at the insecure gateway on a free port.
    port = free_port()
    gateway = clone.serve(
        ".venv/bin/python manage.py cobot_gateway --name cobot1 --port 4841 --insecure "
        "--time-scale 0.05",
        port,
    )
    wait_for_port(port, gateway)
    subprocess.run(
        [sys.executable, "manage.py", "load_demo"],
        cwd=ROOT, env=clone.environment, check=True, capture_output=True, timeout=120,
    )  # fmt: skip
    # Only cobot1 moves to the gateway's port: one endpoint belongs to one cobot.
    move = (
        "from hrc.cobots import services; from hrc.cobots.models import Cobot; "
        "services.update_cobot(Cobot.objects.get(name='cobot1', organisation__slug='demo-plant'), "
        f"endpoint='opc.tcp://127.0.0.1:{port}')"
    )
    subprocess.run(
        [sys.executable, "manage.py", "shell", "-c", move],
        cwd=ROOT, env=clone.environment, check=True, capture_output=True, timeout=120,
    )  # fmt: skip
    powered = clone.run(".venv/bin/python manage.py cobot_call cobot1 PowerOn")
    assert "RobotMode: Running" in powered.stdout
    selected = clone.run(
        ".venv/bin/python manage.py cobot_call cobot1 SelectProgram Coexistence_PickAndPlace"
    )
    assert "CurrentProgram: /programs/Coexistence_PickAndPlace.urp" in selected.stdout
    started = clone.run(".venv/bin/python manage.py cobot_call cobot1 StartProgram")
    assert "ProgramState: Playing" in started.stdout
    stepped = clone.run(
        ".venv/bin/python manage.py cobot_step cobot1 --step 2 --workspace 0 "
        "--pose 0.1 0.2 0.05 0 0 0"
    )
    assert "outcome: ran" in stepped.stdout
    clone.run(".venv/bin/python manage.py cobot_fault cobot1 protective-stop")

    monitor = clone.serve_unported(".venv/bin/python manage.py live_cobots")
    assert monitor.stdout is not None
    assert monitor.stdout.readline().strip() == "live monitor watching cobots"
    time.sleep(1)
    assert monitor.poll() is None


def test_the_docker_load_demo_arguments_register_the_gateways(clone: Clone) -> None:
    # In the README's order: the demo, then each gateway's credentials secret.
    commands = [c for c in all_commands() if c.startswith("docker compose run") and c in RUN_HERE]
    subprocess.run(
        ["bash", "-c", ".venv/bin/python manage.py migrate"], cwd=ROOT, env=clone.environment,
        check=True, capture_output=True, timeout=120,
    )  # fmt: skip
    environment = {
        **clone.environment,
        "COBOT1_GATEWAY_PASSWORD": "p1",
        "COBOT2_GATEWAY_PASSWORD": "p2",
    }

    for command in commands:
        here = re.sub(r"docker compose run --rm (-e \S+ )?web python", ".venv/bin/python", command)
        result = subprocess.run(
            ["bash", "-c", here], cwd=ROOT, env=environment,
            capture_output=True, text=True, timeout=120,
        )  # fmt: skip
        assert result.returncode == 0, result.stderr
    assert len(commands) == 3
