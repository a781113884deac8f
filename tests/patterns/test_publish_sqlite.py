"""On the embedded SQLite, publishing a pattern whose check takes seconds does not hold the
database's one write lock for that time: another writer (a tablet, a job) goes on meanwhile.
Fails when publish_pattern checks the draft inside its transaction."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

from tests.cases.test_run_pattern_embedded import ROOT, embedded_environment


def test_a_slow_check_while_publishing_does_not_stall_other_writers(tmp_path: Path) -> None:
    result = subprocess.run(
        [sys.executable, "-m", "tests.patterns.sqlite_publish"], cwd=ROOT,
        env=embedded_environment(tmp_path), capture_output=True, text=True, timeout=300,
    )  # fmt: skip

    assert result.returncode == 0, result.stderr[-3000:]
    outcome = json.loads(result.stdout.splitlines()[-1])
    assert outcome["published"] == [1]
    assert outcome["check"] > 0.5, outcome  # slow enough to tell the two apart
    assert outcome["write"] < outcome["check"] / 2, outcome
