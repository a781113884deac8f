"""docker/: the compose file and the Dockerfile against the project (Docker itself is not run here).

Every command a service of ours runs (its command, its health check, init's
script, the image's CMD) is parsed by the program it names — a management
command's own parser, Celery's, daphne's — so a renamed command or option
fails here; every variable the compose file interpolates is documented;
secrets are never written in it; what the Dockerfile copies exists.
"""

from __future__ import annotations

import importlib
import importlib.util
import json
import os
import re
import shlex
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
import yaml
from daphne.cli import CommandLineInterface
from django.core.management import CommandError, get_commands, load_command_class

ROOT = Path(__file__).resolve().parents[2]
DOCKER = ROOT / "docker"
COMPOSE: dict[str, Any] = yaml.safe_load((DOCKER / "compose.yaml").read_text())
SERVICES: dict[str, dict[str, Any]] = COMPOSE["services"]
DOCKERFILE = (DOCKER / "Dockerfile").read_text()
# ${NAME}, ${NAME:-default}, ${NAME-default}, ${NAME:?message}, ${NAME?message}; not $${...}.
VARIABLE = re.compile(r"(?<!\$)\$\{([A-Za-z_][A-Za-z0-9_]*)(?:(:?[-?])([^}]*))?\}")
PRODUCTION_SHAPE = {
    "postgres", "redis", "init-hrc", "web", "worker", "beat", "monitor",
    "gateway-cobot1", "gateway-cobot2", "proxy",
}  # fmt: skip
SECRET_NAME = re.compile(r"PASSWORD|SECRET|CREDENTIALS|AUTH|TOKEN")


def _ours() -> dict[str, dict[str, Any]]:
    """The services that run the application image, i.e. hrc's code."""
    return {
        name: service
        for name, service in SERVICES.items()
        if service.get("build", {}).get("target") == "app"
    }


def _interpolated(value: str) -> str:
    """The value as compose would give it, with each variable's default (or a stand-in)."""
    return VARIABLE.sub(lambda m: m.group(3) if m.group(2) in ("-", ":-") else "x", value)


def _argvs(service: dict[str, Any]) -> Iterator[list[str]]:
    """Each command line the service runs: its command (each line of a shell script) and health check."""
    command = [_interpolated(str(part)) for part in service.get("command", [])]
    if command[:2] == ["sh", "-ec"]:
        yield from (shlex.split(line) for line in command[2].splitlines() if line.strip())
    elif command:
        yield command
    test = service.get("healthcheck", {}).get("test", [])
    if test[:1] == ["CMD"]:
        yield [_interpolated(str(part)) for part in test[1:]]


def _dockerfile_cmd() -> list[str]:
    match = re.search(r"^CMD (\[.*\])$", DOCKERFILE, re.MULTILINE)
    assert match is not None, "the Dockerfile has no CMD in exec form"
    return list(json.loads(match.group(1)))


def _check_command(argv: list[str]) -> None:
    """Fails unless `argv` names a program of the project that accepts these arguments."""
    program, *arguments = argv
    if program == "python" and arguments[:1] == ["manage.py"]:
        name, *options = arguments[1:]
        commands = get_commands()
        assert name in commands, f"manage.py has no command {name!r}"
        parser = load_command_class(commands[name], name).create_parser("manage.py", name)
        try:
            parser.parse_args(options)
        except (CommandError, SystemExit) as error:
            pytest.fail(f"manage.py {name} refuses {options}: {error}")
    elif program == "python" and arguments[:1] == ["docker/healthcheck.py"]:
        assert arguments[1] in _healthcheck().CHECKS, arguments
    elif program == "celery":
        assert arguments[:2] == ["-A", "hrc"], argv
        assert arguments[2] in ("worker", "beat"), argv
        # Click reports an unknown option before it acts on --help.
        result = subprocess.run(
            [sys.executable, "-m", "celery", *arguments, "--help"],
            cwd=ROOT, capture_output=True, text=True, timeout=60,
            env={**os.environ, "DJANGO_SETTINGS_MODULE": "hrc.settings.test"},
        )  # fmt: skip
        assert result.returncode == 0, f"{argv}: {result.stderr}"
    elif program == "daphne":
        options = CommandLineInterface().parser.parse_args(arguments)
        module, _, attribute = options.application.partition(":")
        application = getattr(importlib.import_module(module), attribute)
        assert callable(application)
    else:
        pytest.fail(f"{argv}: not a command this test knows how to check")


def _healthcheck() -> Any:
    spec = importlib.util.spec_from_file_location("healthcheck", DOCKER / "healthcheck.py")
    assert spec is not None
    assert spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _documented() -> set[str]:
    """Names written in backticks in docker/README.md and in the settings page of the docs."""
    text = (DOCKER / "README.md").read_text() + (ROOT / "docs" / "settings.md").read_text()
    return set(re.findall(r"`([A-Z][A-Z0-9_]+)`", text))


def test_the_production_shape_is_all_there_with_a_health_check_on_each_lasting_service() -> None:
    assert set(SERVICES) == PRODUCTION_SHAPE
    for name, service in SERVICES.items():
        if name == "init-hrc":
            assert service["restart"] == "no"
            assert "healthcheck" not in service
            continue
        test = service["healthcheck"]["test"]
        assert test[0] in ("CMD", "CMD-SHELL"), name
        assert len(test) > 1, name
    for name, service in SERVICES.items():
        for other, condition in service.get("depends_on", {}).items():
            assert other in SERVICES, (name, other)
            wanted = "service_completed_successfully" if other == "init-hrc" else "service_healthy"
            assert condition["condition"] == wanted, (name, other)
    for name in set(_ours()) - {"init-hrc"}:
        assert "init-hrc" in SERVICES[name]["depends_on"], f"{name} may start before init-hrc"


@pytest.mark.parametrize("name", sorted(_ours()))
def test_each_command_of_a_service_is_a_command_of_the_project_with_options_it_accepts(
    name: str,
) -> None:
    argvs = list(_argvs(SERVICES[name]))
    assert argvs
    for argv in argvs:
        _check_command(argv)


def test_the_image_serves_with_daphne_and_nothing_runs_the_development_server() -> None:
    cmd = _dockerfile_cmd()
    assert cmd[0] == "daphne"
    _check_command(cmd)
    for text in (DOCKERFILE, (DOCKER / "compose.yaml").read_text()):
        assert "runserver" not in text
        assert "--insecure" not in text  # the gateways are secured off loopback
    web = SERVICES["web"]["command"]
    assert web[0] == "daphne"
    assert web[web.index("--port") + 1] == "8000"
    assert "port 8000" in (DOCKER / "Caddyfile").read_text()


def test_every_variable_the_compose_file_needs_is_documented() -> None:
    text = (DOCKER / "compose.yaml").read_text()
    variables = {match.group(1) for match in VARIABLE.finditer(text)}
    assert {"SECRET_KEY", "POSTGRES_PASSWORD", "REDIS_PASSWORD"} <= variables
    environment_names = {key for s in _ours().values() for key in s.get("environment", {})}
    missing = (variables | environment_names) - _documented()
    assert not missing, f"not documented in docker/README.md or docs/settings.md: {missing}"


def test_secrets_come_from_the_environment_and_a_missing_one_stops_compose() -> None:
    text = (DOCKER / "compose.yaml").read_text()
    for match in VARIABLE.finditer(text):
        name, operator = match.group(1), match.group(2)
        # Without a default compose would pass an empty string: such a variable must be required.
        assert operator is not None, f"${{{name}}} has neither a default nor :?message"
        if operator in ("?", ":?"):
            assert operator == ":?", f"{name}: an empty value must stop compose too (:?)"
            assert match.group(3).strip(), f"{name}: the message should say what to set"
        if SECRET_NAME.search(name):
            assert operator == ":?", f"{name} is a secret: required, never a default"
    for name, service in SERVICES.items():
        for key, value in (service.get("environment") or {}).items():
            if SECRET_NAME.search(key):
                assert "${" in str(value), f"{name}: {key} is written in the file"


def test_what_the_dockerfile_copies_exists_and_reaches_the_build() -> None:
    stages = re.findall(r"^FROM (\S+) AS (\S+)$", DOCKERFILE, re.MULTILINE)
    names = {stage for _, stage in stages}
    assert ("python:3.11-slim", "app") in stages
    for service in SERVICES.values():
        if "build" in service:
            build = service["build"]
            assert (
                DOCKER / build["context"] / build["dockerfile"]
            ).resolve() == DOCKER / "Dockerfile"
            assert build["target"] in names
    app = DOCKERFILE.split("AS app", 1)[1].split("\nFROM ", 1)[0]
    user = re.search(r"^USER (\S+)$", app, re.MULTILINE)
    assert user is not None
    assert user.group(1) not in ("root", "0")
    ignore = (DOCKER / "Dockerfile.dockerignore").read_text().splitlines()
    included = [line[1:].rstrip("/") for line in ignore if line.startswith("!")]
    copies = re.findall(r"^COPY (?!--from)(.+)$", DOCKERFILE, re.MULTILINE)
    assert copies
    for copy in copies:
        for source in shlex.split(copy)[:-1]:
            path = source.rstrip("/")
            assert (ROOT / path).exists(), f"COPY {source}: no such path in the repository"
            assert any(path == kept or path.startswith(f"{kept}/") for kept in included), (
                f"COPY {source}: Dockerfile.dockerignore leaves it out of the build context"
            )
    lock_pins = {
        line.split("==")[0].lower() for line in (ROOT / "requirements/lock.txt").read_text().splitlines()
        if "==" in line and not line.startswith("#")
    }  # fmt: skip
    for requirement in (ROOT / "requirements/base.in").read_text().splitlines():
        name = re.split(r"[\[<>=~ ]", requirement.strip(), maxsplit=1)[0].lower()
        if name and not name.startswith("#"):
            assert name in lock_pins, f"{name} of base.in has no pinned version in lock.txt"
