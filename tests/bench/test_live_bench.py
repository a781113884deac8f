"""The live-layer benchmark: its pattern and options, and a quick run end to end in a child
process (as `make bench` starts it), which must leave no database behind."""

import json
import subprocess
import sys
from pathlib import Path

import psycopg
import pytest

from bench.live import QUICK, Settings, parse_args, pattern
from bench.runtime_rig import ROOT, database_server
from hrc.engine import check_document


def test_the_bench_pattern_is_publishable() -> None:
    report = check_document(pattern())

    assert report.valid, [issue.message for issue in report.errors]
    assert report.sound is True


def test_quick_sets_the_small_sizes_and_explicit_options_win() -> None:
    settings = parse_args(["--quick", "--clients", "7"])

    assert settings.clients == 7
    assert settings.samples == QUICK["samples"]
    assert parse_args([]) == Settings()


@pytest.mark.parametrize("arguments", [["--clients", "0"], ["--samples", "0"], ["--warmup", "-1"]])
def test_nonsense_options_are_refused(arguments: list[str]) -> None:
    with pytest.raises(SystemExit):
        parse_args(arguments)


def test_a_quick_run_writes_the_report_and_leaves_nothing_behind(tmp_path: Path) -> None:
    command = [sys.executable, "-m", "bench.live", "--quick", "--results-dir", str(tmp_path)]
    child = subprocess.Popen(command, cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
    output, _ = child.communicate(timeout=600)
    assert child.returncode == 0, output.decode(errors="replace")[-6000:]

    report = json.loads((tmp_path / "live-latest.json").read_text())
    samples = QUICK["clients"] * QUICK["samples"]
    assert report["ours"]["n"] == samples
    assert 0 < report["ours"]["p50_ms"] <= report["ours"]["p99_ms"]
    assert report["floor"]["n"] == QUICK["clients"] * QUICK["floor_samples"]
    assert 0 < report["floor"]["p50_ms"] <= report["floor"]["p99_ms"]
    assert report["ratio_p50"] > 0
    assert report["register_to_offer_recorded"]["n"] == QUICK["samples"]
    assert isinstance(report["meets_target"], bool)
    assert "target p99 <= 100 ms" in output.decode()
    with psycopg.connect(f"{database_server()}/postgres") as connection:
        left = connection.execute(
            "SELECT datname FROM pg_database WHERE datname = %s", (f"hrc_bench_{child.pid}",)
        ).fetchall()
    assert left == []
