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
from django.db import connection, transaction

from bench.runtime import (
    flatness_verdict,
    parse_args,
    signalling_verdict,
    throughput_verdict,
    verdict,
)
from bench.runtime_rig import (
    QUICK,
    ROOT,
    Settings,
    StatementCounter,
    database_server,
    loop_pattern,
    signal_pattern,
)
from hrc.cases import dispatch
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


def _row(workers: int, rate: float) -> dict[str, Any]:
    return {"workers": workers, "cases_per_second": rate}


def test_signalling_meets_its_target_only_within_twice_and_thrice_the_orm_floor_sum() -> None:
    floor = {"p50_ms": 10.0, "p99_ms": 20.0}

    within = signalling_verdict({"p50_ms": 19.9, "p99_ms": 59.9}, floor)
    slow_tail = signalling_verdict({"p50_ms": 19.9, "p99_ms": 60.1}, floor)
    slow_middle = signalling_verdict({"p50_ms": 20.1, "p99_ms": 30.0}, floor)

    assert within["meets_target"] is True
    assert within["target"] | {"p50_ms": 20.0, "p99_ms": 60.0} == within["target"]
    assert within["target"]["floor"] == "floor_sum_orm"
    assert slow_tail["meets_target"] is False
    assert slow_middle["meets_target"] is False
    # Issue 4's absolute figures stay beside it, as information.
    assert within["old_absolute_target"]["met"] is False


def test_throughput_is_judged_by_the_best_two_worker_row_against_half_the_cpu_bound() -> None:
    rows = [_row(1, 90.0), _row(2, 49.0), _row(2, 51.0)]

    met = throughput_verdict(rows, bound=100.0)
    missed = throughput_verdict([_row(1, 90.0), _row(2, 49.0)], bound=100.0)

    assert met["meets_target"] is True
    assert met["best_cases_per_second"] == 51.0
    assert met["share_of_cpu_bound"] == 0.51
    assert met["target"] == {"workers": 2, "share_of_cpu_bound": 0.5, "cases_per_second": 50.0}
    # One worker's 90 cases/s does not count: the target is with two.
    assert missed["meets_target"] is False


@pytest.mark.parametrize(("rows", "bound"), [([_row(1, 90.0)], 100.0), ([_row(2, 90.0)], None)])
def test_throughput_without_a_two_worker_row_or_a_cpu_bound_is_not_judged(
    rows: list[dict[str, Any]], bound: float | None
) -> None:
    result = throughput_verdict(rows, bound)

    assert result["meets_target"] is None
    assert verdict(result["meets_target"]) == "not measured"


def test_a_step_is_flat_while_the_long_case_costs_at_most_a_quarter_more() -> None:
    assert flatness_verdict(1.25)["meets_target"] is True
    assert flatness_verdict(1.26)["meets_target"] is False
    assert verdict(True) == "meets"
    assert verdict(False) == "MISSES"


@pytest.mark.django_db(transaction=True)
def test_the_counter_splits_statements_between_a_block_and_the_tasks_it_dispatched() -> None:
    counter = StatementCounter()

    with dispatch.run_inline(counter), counter.phase("completion"), transaction.atomic():
        with connection.cursor() as cursor:
            cursor.execute("SELECT 1")
            cursor.execute("SELECT 2")
        dispatch.send_on_commit(dispatch.Task.PURGE_MESSAGES)
        dispatch.send_on_commit(dispatch.Task.PURGE_MESSAGES)

    completion = counter.counts["completion"]
    purge = counter.counts[dispatch.Task.PURGE_MESSAGES.value]
    assert completion["statements"] == 2  # the task's statements are not the block's
    assert completion["transaction_control"] == 2  # BEGIN and COMMIT
    assert completion["runs"] == 1
    assert purge["runs"] == 2
    assert purge["statements"] >= 2  # each run deletes what expired, at least one statement
    assert set(counter.counts) == {"completion", dispatch.Task.PURGE_MESSAGES.value}


def test_a_call_that_is_no_registered_task_goes_unnamed() -> None:
    assert StatementCounter.task_name(lambda: None) == StatementCounter.UNNAMED_TASK


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
    limit = signalling["target"]["p50_ms"]
    assert limit == pytest.approx(2 * floors["floor_sum_orm"]["p50_ms"], abs=0.01)

    throughput = report["throughput"]
    assert throughput["cobots"] == QUICK["cobots"]
    assert [row["workers"] for row in throughput["rows"]] == [1, 2]
    assert set(throughput["floors"]) == {"celery_tasks_per_second", "steps_per_second"}
    assert all(rate > 0 for rate in throughput["floors"].values())
    cpu = throughput["floor_cpu_ms"]
    assert set(cpu) == {"celery_task", "step", "orm_transaction"}
    assert all(ms > 0 for ms in cpu.values())
    # The ceiling's floors are measured on both sides of the rows; their mean is the one used.
    before, after = throughput["floor_cpu_ms_before_and_after"]
    for name, ms in cpu.items():
        assert before[name] > 0
        assert after[name] > 0
        assert ms == pytest.approx((before[name] + after[name]) / 2, abs=0.001)
    bound = throughput["cores"] * 1000 / sum(cpu.values())
    assert throughput["floor_cpu_bound_cases_per_second"] == pytest.approx(bound, abs=0.1)
    assert isinstance(throughput["meets_target"], bool)
    two = max(row["cases_per_second"] for row in throughput["rows"] if row["workers"] == 2)
    assert throughput["share_of_cpu_bound"] == pytest.approx(two / bound, abs=0.001)
    statements = throughput["statements_per_case"]
    # The completion and the job the worker runs both touch the database; the total adds up.
    assert statements["phases"]["completion"]["statements"] > 0
    # The step the completion leased for its free cobot, driven by the task its message ran.
    assert statements["phases"][dispatch.Task.RUN_LEASED_JOB.value]["runs"] >= 1
    assert statements["phases"][dispatch.Task.RUN_LEASED_JOB.value]["statements"] > 0
    assert statements["total"]["statements"] == pytest.approx(
        sum(row["statements"] for row in statements["phases"].values()), abs=0.05
    )
    for row in throughput["rows"]:
        assert row["cases"] == QUICK["cases"]
        assert row["warmup_cases"] == max(10, 4 * QUICK["cobots"] * row["workers"])
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
    assert log["meets_target"] == (log["ratio_p50"] <= 1.25)

    assert report["machine"]["postgresql"]
    assert report["machine"]["celery"]
    assert list(tmp_path.glob("runtime-2*.json"))
    # The table went to stdout with the three parts.
    assert all(part in output.decode() for part in ("(a) Step", "(b) Throughput", "(c) One"))
    assert output.decode().count("target ") == 3
    assert "SQL statements per case" in output.decode()
    with psycopg.connect(f"{database_server()}/postgres") as connection:
        left = connection.execute(
            "SELECT datname FROM pg_database WHERE datname = %s", (f"hrc_bench_{child.pid}",)
        ).fetchall()
    assert left == []
