"""The runtime benchmark: its patterns and options, and a quick run end to end.

The run is a child process, as `make bench` starts it: it creates its own
database, broker, workers and gateways, and must leave none of them behind.
"""

import json
import subprocess
import sys
from pathlib import Path
from typing import Any

import psycopg
import pytest

from bench.runtime import parse_args
from bench.runtime_rig import (
    QUICK,
    ROOT,
    Settings,
    database_server,
    loop_pattern,
    signal_pattern,
)
from hrc.engine import check_document


@pytest.mark.parametrize("document", [signal_pattern(), loop_pattern()], ids=["signal", "loop"])
def test_the_bench_patterns_are_publishable(document: dict[str, Any]) -> None:
    report = check_document(document)

    assert report.valid, [issue.message for issue in report.errors]
    assert report.sound is True


def test_the_floor_app_leaves_hrcs_tasks_on_hrcs_app() -> None:
    # This module imported the rig, and with it the floor's Celery app: hrc's shared tasks
    # must still go through hrc's app and its broker, not the floor's (memory://).
    from celery import current_app

    from hrc.cases import tasks
    from hrc.celery import app

    assert current_app.main == app.main == "hrc"
    assert tasks.run_job.app is app


def test_quick_sets_the_small_sizes_and_explicit_options_win() -> None:
    settings = parse_args(["--quick", "--steps", "7", "--workers", "2,1"])

    assert settings.steps == 7
    assert settings.cases == QUICK["cases"]
    assert settings.workers == (2, 1)
    assert parse_args([]) == Settings()


@pytest.mark.parametrize("arguments", [["--steps", "0"], ["--workers", "0"], ["--workers", "x"]])
def test_nonsense_options_are_refused(arguments: list[str]) -> None:
    with pytest.raises(SystemExit):
        parse_args(arguments)


def _positive_summary(row: dict[str, Any], n: int | None = None) -> None:
    assert 0 < row["min_ms"] <= row["p50_ms"] <= row["p99_ms"] <= row["max_ms"]
    if n is not None:
        assert row["n"] == n


def test_a_quick_run_writes_the_report_and_leaves_nothing_behind(tmp_path: Path) -> None:
    command = [sys.executable, "-m", "bench.runtime", "--quick", "--results-dir", str(tmp_path)]
    child = subprocess.Popen(command, cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
    output, _ = child.communicate(timeout=900)
    assert child.returncode == 0, output.decode(errors="replace")[-6000:]

    report = json.loads((tmp_path / "runtime-latest.json").read_text())
    signalling = report["signalling"]
    _positive_summary(signalling["ours"], n=QUICK["steps"])
    for row in ("http_response", "to_lease"):
        assert signalling[row]["n"] == QUICK["steps"]
    floors = signalling["floors"]
    for name in ("opcua_write", "opcua_write_seen", "celery_dispatch", "db_commit", "orm_transaction"):  # fmt: skip
        _positive_summary(floors[name], n=QUICK["floor_samples"])
        assert signalling["ratio_p50"][name] > 0
        assert signalling["ratio_p99"][name] > 0
    # The ORM's transaction does more than a bare commit, and the sums add their parts.
    assert floors["orm_transaction"]["p50_ms"] > floors["db_commit"]["p50_ms"]
    for name in ("floor_sum", "floor_sum_orm"):
        parts = floors[name]["of"]
        assert floors[name]["p50_ms"] == pytest.approx(sum(floors[p]["p50_ms"] for p in parts), abs=0.01)  # fmt: skip
    assert floors["floor_sum_orm"]["p50_ms"] > floors["floor_sum"]["p50_ms"]
    assert isinstance(signalling["meets_target"], bool)

    throughput = report["throughput"]
    assert throughput["cobots"] == QUICK["cobots"]
    assert [row["workers"] for row in throughput["rows"]] == [1, 2]
    assert set(throughput["floors"]) == {"celery_tasks_per_second", "steps_per_second"}
    assert all(rate > 0 for rate in throughput["floors"].values())
    cpu = throughput["floor_cpu_ms"]
    assert set(cpu) == {"celery_task", "step", "orm_transaction"}
    assert all(ms > 0 for ms in cpu.values())
    bound = throughput["cores"] * 1000 / sum(cpu.values())
    assert throughput["floor_cpu_bound_cases_per_second"] == pytest.approx(bound, abs=0.1)
    for row in throughput["rows"]:
        assert row["cases"] == QUICK["cases"]
        assert row["cases_per_second"] > 0
        assert set(row["ratio_to_floors"]) == set(throughput["floors"])
        assert row["seconds"] > 0
        _positive_summary(row["job_lease_to_end"], n=QUICK["cases"])

    log = report["log_length"]
    assert 10 <= log["short"]["events_before"] < 20
    assert 1000 <= log["long"]["events_before"] < log["long"]["events_after"]
    for row in ("short", "long"):
        _positive_summary(log[row], n=QUICK["repeats"])
    assert log["ratio_p50"] > 0

    assert report["machine"]["postgresql"]
    assert report["machine"]["celery"]
    assert list(tmp_path.glob("runtime-2*.json"))
    # The table went to stdout with the three parts.
    assert all(part in output.decode() for part in ("(a) Step", "(b) Throughput", "(c) One"))
    with psycopg.connect(f"{database_server()}/postgres") as connection:
        left = connection.execute(
            "SELECT datname FROM pg_database WHERE datname = %s", (f"hrc_bench_{child.pid}",)
        ).fetchall()
    assert left == []
