"""hrc.database.ensure_migrated: a command run on a database that is missing or not migrated
says in one line what to run, with no traceback; run_pattern migrates the embedded SQLite."""

from __future__ import annotations

import sqlite3
import subprocess
import sys
from pathlib import Path

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
