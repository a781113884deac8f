"""The embedded SQLite keeps concurrent writers correct: two operators completing their
parallel tasks of the same case at the same moment (threads, each with its own connection)
meet no "database is locked" and lose no update — every case records both completions and
offers the join. With a DEFERRED begin (SQLite's default) the second writer's lock upgrade
fails at once with "database is locked"; IMMEDIATE (hrc/settings/base.py) queues it. The
runtime's select_for_update forms (of, no_key, skip_locked, nowait) raise no
NotSupportedError there: Django drops them on a database without row locks."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

from tests.cases.test_run_pattern_embedded import ROOT, embedded_environment

CASES = 20


def test_two_operators_completing_one_case_at_once_lose_nothing_on_sqlite(tmp_path: Path) -> None:
    result = subprocess.run(
        [sys.executable, "-m", "tests.cases.sqlite_writers", str(CASES)],
        cwd=ROOT,
        env=embedded_environment(tmp_path),
        capture_output=True,
        text=True,
        timeout=300,
    )

    assert result.returncode == 0, result.stderr[-3000:]
    assert "database is locked" not in result.stderr
    outcome = json.loads(result.stdout.splitlines()[-1])
    assert outcome["errors"] == []
    assert outcome["row_locks"] == CASES  # no NotSupportedError; only cases, no cobot or job
    assert len(outcome["cases"]) == CASES
    # An operator's write does not wait for a cobot pause that waits on a silent gateway.
    pause = outcome["pause"]
    assert pause["pause_seconds"] > 2, pause
    assert pause["write_seconds"] < 1, pause
    assert pause["paused_at"] == "None", pause
    assert pause["error"].startswith("pause: "), pause
    for case in outcome["cases"]:
        assert case == {"completed": ["left", "prepare", "right"], "open": ["join"]}
