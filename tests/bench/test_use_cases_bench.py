"""The use cases' benchmark: its options, its arithmetic, and a quick run end to end in a child
process (as `make bench` starts it), which must leave no database behind."""

import json
import subprocess
import sys
from pathlib import Path

import psycopg
import pytest

from bench.runtime_rig import ROOT, database_server
from bench.use_cases import QUICK, Settings, _union, parse_args, use_case_files


def test_the_union_of_task_times_counts_overlaps_once() -> None:
    assert _union([]) == 0
    assert _union([(0, 2), (1, 3), (5, 6)]) == 4
    assert _union([(5, 6), (0, 10)]) == 10


def test_quick_sets_the_small_sizes_and_explicit_options_win() -> None:
    settings = parse_args(["--quick", "--rounds", "2", "--only", "2,5_polishing"])

    assert settings.rounds == 2
    assert settings.time_scale == QUICK["time_scale"]
    assert [path.stem for path in use_case_files(settings.only)] == [
        "2_extended_spot_taping",
        "5_polishing",
    ]
    assert parse_args([]) == Settings()
    assert len(use_case_files()) == 9  # the seven and two of hrc's variants


@pytest.mark.parametrize(
    "arguments",
    [["--rounds", "0"], ["--workers", "0"], ["--time-scale", "0"], ["--only", "8"]],
)
def test_nonsense_options_are_refused(arguments: list[str]) -> None:
    with pytest.raises(SystemExit):
        parse_args(arguments)


def test_a_quick_run_writes_the_report_and_leaves_nothing_behind(tmp_path: Path) -> None:
    command = [sys.executable, "-m", "bench.use_cases", "--quick", "--only", "2,6",
               "--results-dir", str(tmp_path)]  # fmt: skip
    child = subprocess.Popen(command, cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
    output, _ = child.communicate(timeout=900)
    assert child.returncode == 0, output.decode(errors="replace")[-6000:]

    report = json.loads((tmp_path / "use-cases-latest.json").read_text())
    assert report["settings"]["time_scale"] == QUICK["time_scale"]
    rows = {row["file"]: row for row in report["use_cases"]}
    assert set(rows) == {"2_extended_spot_taping.json", "6_fixture.json"}
    assert rows["2_extended_spot_taping.json"]["cases_per_round"] == 2  # both operators at once
    for row in rows.values():
        summary = row["summary"]
        assert summary["completed"] == summary["cases"] == len(row["cases"]) >= 1
        for case in row["cases"]:
            assert case["completed"]
            assert case["cycle_s"] >= case["busy_s"] > 0  # the floor holds
            assert case["cobot_sum_s"] > 0
            assert case["operator_sum_s"] > 0
            assert case["tasks_sum_s"] >= case["busy_s"] - 1e-3
            assert 0 <= case["orchestration_share"] < 1
            assert case["idle_s"] == pytest.approx(case["cycle_s"] - case["busy_s"], abs=1e-3)
    assert list(tmp_path.glob("use-cases-2*.json"))
    assert "Use cases:" in output.decode()
    with psycopg.connect(f"{database_server()}/postgres") as connection:
        left = connection.execute(
            "SELECT datname FROM pg_database WHERE datname = %s", (f"hrc_bench_{child.pid}",)
        ).fetchall()
    assert left == []
