"""hrc.database.ensure_migrated: a command run on a database that is missing or not migrated
says in one line what to run, with no traceback; run_pattern migrates the embedded SQLite
(only that one: a PostgreSQL database it reports like the others)."""

from __future__ import annotations

import sqlite3
import subprocess
import sys
import uuid
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import psycopg
import pytest
from django.conf import settings
from django.db import connection

from hrc.cobots.simulated import free_port
from tests.cases.test_run_pattern_embedded import ROOT, embedded_environment


def manage(scratch: Path, *arguments: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "manage.py", *arguments],
        cwd=ROOT,
        env=embedded_environment(scratch),
        capture_output=True,
        text=True,
        timeout=120,
    )


def test_a_cobot_command_on_a_fresh_clone_says_to_migrate(tmp_path: Path) -> None:
    result = manage(tmp_path, "cobot_call", "cobot1", "PowerOn")  # no var/ yet

    assert result.returncode == 1
    assert "Traceback" not in result.stderr
    [line] = result.stderr.strip().splitlines()
    assert "is not migrated" in line
    assert "`.venv/bin/python manage.py migrate`" in line


def test_a_sqlite_database_whose_folder_is_missing_is_named(tmp_path: Path) -> None:
    missing = tmp_path / "missing" / "hrc.sqlite3"
    environment = embedded_environment(tmp_path) | {"DATABASE_URL": f"sqlite:///{missing}"}

    result = subprocess.run(
        [sys.executable, "manage.py", "live_cobots"], cwd=ROOT, env=environment,
        capture_output=True, text=True, timeout=120,
    )  # fmt: skip

    assert result.returncode == 1
    assert "Traceback" not in result.stderr
    [line] = result.stderr.strip().splitlines()
    assert f"Cannot open the SQLite database {missing} (unable to open database file)" in line


def test_a_command_on_a_database_never_migrated_says_to_migrate(tmp_path: Path) -> None:
    (tmp_path / "var").mkdir()
    sqlite3.connect(tmp_path / "var" / "hrc.sqlite3").close()  # exists, no tables

    for arguments in (("cobot_call", "cobot1", "PowerOn"), ("live_cobots",), ("load_demo",)):
        result = manage(tmp_path, *arguments)

        assert result.returncode == 1, arguments
        assert "Traceback" not in result.stderr, result.stderr
        [line] = result.stderr.strip().splitlines()
        assert "is not migrated" in line
        assert "`.venv/bin/python manage.py migrate`" in line


def test_run_pattern_creates_and_migrates_the_embedded_database_it_needs(tmp_path: Path) -> None:
    pattern = ROOT / "hrc" / "patterns" / "examples" / "synch_1o1c_assembly.json"

    result = manage(
        tmp_path, "run_pattern", str(pattern), "--simulate", "--time-scale", "0", "--json"
    )

    assert result.returncode == 0, result.stderr[-3000:]
    assert result.stdout.splitlines()[-1].endswith('"event": "case-completed"}')
    assert (tmp_path / "var" / "hrc.sqlite3").exists()
    again = manage(tmp_path, "cobot_call", "cobot1", "PowerOn")
    assert "No registered cobot is named 'cobot1'" in again.stderr  # migrated: past the check


@pytest.fixture
def empty_postgresql() -> Iterator[str]:
    """A new PostgreSQL database with no tables, on the tests' server; its URL."""
    server = settings.DATABASES["default"]
    name = f"hrc_unmigrated_{uuid.uuid4().hex[:12]}"
    params: dict[str, Any] = {
        key: value
        for key, value in {
            "host": server["HOST"], "port": server["PORT"],
            "user": server["USER"], "password": server["PASSWORD"],
        }.items()
        if value
    }  # fmt: skip
    with psycopg.connect(dbname="postgres", autocommit=True, **params) as admin:
        admin.execute(f'CREATE DATABASE "{name}"')
    try:
        password = f":{server['PASSWORD']}" if server["PASSWORD"] else ""
        yield f"postgres://{server['USER']}{password}@{server['HOST']}:{server['PORT']}/{name}"
    finally:
        with psycopg.connect(dbname="postgres", autocommit=True, **params) as admin:
            admin.execute(f'DROP DATABASE IF EXISTS "{name}" WITH (FORCE)')


def test_on_a_postgresql_database_never_migrated_every_command_says_to_migrate(
    tmp_path: Path, empty_postgresql: str
) -> None:
    environment = embedded_environment(tmp_path) | {"DATABASE_URL": empty_postgresql}
    pattern = ROOT / "hrc" / "patterns" / "examples" / "synch_1o1c_assembly.json"

    # run_pattern too: a shared PostgreSQL database is migrated by a person, not by it.
    for arguments in (
        ("run_pattern", str(pattern), "--simulate", "--time-scale", "0", "--json"),
        ("cobot_call", "cobot1", "PowerOn"),
        ("load_demo",),
    ):
        result = subprocess.run(
            [sys.executable, "manage.py", *arguments], cwd=ROOT, env=environment,
            capture_output=True, text=True, timeout=120,
        )  # fmt: skip

        assert result.returncode == 1, arguments
        assert "Traceback" not in result.stderr, result.stderr
        [line] = result.stderr.strip().splitlines()
        assert "The postgresql database hrc_unmigrated_" in line
        assert "is not migrated" in line
        assert "run `.venv/bin/python manage.py migrate` first" in line


def test_a_postgresql_server_that_does_not_answer_is_named_at_once(tmp_path: Path) -> None:
    environment = embedded_environment(tmp_path) | {
        "DATABASE_URL": f"postgres://postgres@127.0.0.1:{free_port()}/hrc",
    }

    result = subprocess.run(
        [sys.executable, "manage.py", "live_cobots"], cwd=ROOT, env=environment,
        capture_output=True, text=True, timeout=120,
    )  # fmt: skip

    assert result.returncode == 1
    # One line with the cause, not the pool's repeated log lines and its timeout.
    [line] = result.stderr.strip().splitlines()
    assert "Cannot open the postgresql database hrc (connection failed:" in line
    assert "Connection refused" in line


@pytest.mark.django_db
def test_no_statement_on_postgresql_runs_longer_than_the_timeout() -> None:
    with connection.cursor() as cursor:
        cursor.execute("SHOW statement_timeout")
        [(timeout,)] = cursor.fetchall()
    assert timeout == "30s"
