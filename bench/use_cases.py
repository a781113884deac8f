"""`make bench` (fifth part): the use cases — each one's cycle time against its task times.

Every use case of hrc/patterns/examples/use_cases/ runs as `run_pattern
--simulate` runs it, but on real Celery workers (WORKERS, prefork, concurrency
1; the first runs the beat and so the sweeper) with a private redis-server
as the broker, in a scratch PostgreSQL database (hrc_bench_<pid>: created,
migrated, dropped), against simulated OPC UA gateways at --time-scale (0.1:
robot time ten times faster) and simulated operators who complete a task
0.2–1.0 s of robot time after it starts. A round is one case, or one case
per operator where the model says its cases differ (the extended spot
taping's queue variant runs both operators' cases at once; the thesis' one
has both operators' processes in one case); --rounds rounds per use case.

From each case's event log:

- cycle: case started → case completed;
- cobot Σ, operator Σ: the sum of its cobot (steps and device calls) and its
  operator tasks' times, each from task started to task completed;
- busy: the time at least one of its tasks was running, the union of those
  intervals. That is the floor, measured in the same run: with these task
  times no orchestration could end the case sooner;
- idle = cycle − busy: the time in which no task of the case ran, only hrc
  (offers, doorbells, leases, handshakes, the firing rule). The
  orchestration's share is idle / cycle; per task, idle / tasks. Parallel
  branches hide part of it (Σ tasks can exceed the cycle); the share counts
  only what nobody's work covered.

Results: bench/results/use-cases-<UTC>.json (and -latest.json), and a table.
Wall seconds at the time scale: the cobot's share shrinks as robot time is
scaled down, the orchestration's does not, so compare shares at one scale.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import signal
import statistics
import sys
import tempfile
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field, replace
from datetime import UTC, datetime
from pathlib import Path
from typing import TYPE_CHECKING, Any

from bench.report import load_average, print_load, settings_json, write_results
from bench.runtime_rig import (
    RESULTS_DIR,
    ROOT,
    SETTINGS_MODULE,
    _set_up_django,
    database_server,
    scratch_database,
)

if TYPE_CHECKING:  # Django's models load only after django.setup(), inside the functions
    from tests.support.workers import RedisProcess, WorkerProcess

USE_CASES_DIR = ROOT / "hrc" / "patterns" / "examples" / "use_cases"
CASE_TIMEOUT = 600.0
# As docker/README.md sizes them: two slots per cobot, for its step and the pause or resume a
# space constraint sends it meanwhile, and one for device calls (with two, 4b's pauses never
# arrived while the steps held both).
WORKERS = 5


@dataclass(frozen=True)
class Settings:
    time_scale: float = 0.1
    rounds: int = 3
    workers: int = WORKERS
    only: tuple[str, ...] = ()  # file stems or numbers ("2", "2b"); empty: all of them
    quick: bool = False
    results_dir: Path = field(default=RESULTS_DIR, compare=False)


QUICK: dict[str, Any] = {"time_scale": 0.02, "rounds": 1}


def use_case_files(only: Sequence[str] = ()) -> list[Path]:
    """The use cases' files in their order; `only` picks by stem or by number ("5")."""
    files = sorted(USE_CASES_DIR.glob("*.json"))
    if not only:
        return files
    return [path for path in files if path.stem in only or path.stem.split("_", 1)[0] in only]


# Measuring one case from its event log ---------------------------------------------------------


def case_times(case_id: int) -> dict[str, Any]:
    """Cycle, task sums, busy union and idle time of one ended case, in seconds."""
    from hrc.cases.choices import EventType, WorkItemKind
    from hrc.cases.models import Case, CaseEvent

    case = Case.objects.get(pk=case_id)
    events = CaseEvent.objects.filter(case_id=case_id).order_by("seq")
    started: dict[int, float] = {}
    spans: list[tuple[float, float, str]] = []  # (start, end, kind) per task run
    begin = end = None
    for event in events.select_related("work_item"):
        at = event.at.timestamp()
        if event.type == EventType.CASE_STARTED:
            begin = at
        elif event.type == EventType.CASE_COMPLETED:
            end = at
        elif event.type == EventType.TASK_STARTED and event.work_item_id is not None:
            started[event.work_item_id] = at
        elif event.type == EventType.TASK_COMPLETED and event.work_item_id in started:
            item = event.work_item
            assert item is not None  # it has an id
            spans.append((started.pop(item.pk), at, item.kind))
    if begin is None or end is None:
        return {"case": case_id, "status": case.status, "completed": False}
    cycle = end - begin
    busy = _union([(a, b) for a, b, _ in spans])
    cobot = sum(b - a for a, b, kind in spans if kind != WorkItemKind.OPERATOR)
    operator = sum(b - a for a, b, kind in spans if kind == WorkItemKind.OPERATOR)
    idle = max(cycle - busy, 0.0)
    return {
        "case": case_id,
        "status": case.status,
        "completed": True,
        "tasks": len(spans),
        "cobot_tasks": sum(1 for *_, kind in spans if kind != WorkItemKind.OPERATOR),
        "cycle_s": round(cycle, 4),
        "cobot_sum_s": round(cobot, 4),
        "operator_sum_s": round(operator, 4),
        "tasks_sum_s": round(cobot + operator, 4),
        "busy_s": round(busy, 4),
        "idle_s": round(idle, 4),
        "cycle_over_busy": round(cycle / busy, 3) if busy else None,
        "orchestration_share": round(idle / cycle, 4) if cycle else None,
        "idle_ms_per_task": round(idle * 1000 / len(spans), 2) if spans else None,
    }


def _union(intervals: Sequence[tuple[float, float]]) -> float:
    """The length of the union of [start, end] intervals."""
    total, reach = 0.0, None
    for start, end in sorted(intervals):
        if reach is None or start > reach:
            total += end - start
            reach = end
        elif end > reach:
            total += end - reach
            reach = end
    return total


def summarise(cases: Sequence[Mapping[str, Any]]) -> dict[str, Any]:
    """Medians over the completed cases of a use case (and how many did not complete)."""
    done = [case for case in cases if case["completed"]]
    keys = ("cycle_s", "cobot_sum_s", "operator_sum_s", "tasks_sum_s", "busy_s", "idle_s",
            "cycle_over_busy", "orchestration_share", "idle_ms_per_task", "tasks")  # fmt: skip
    medians = {
        key: round(statistics.median(case[key] for case in done), 4) if done else None
        for key in keys
    }
    return {"cases": len(cases), "completed": len(done), **medians}


# The run ---------------------------------------------------------------------------------------


@contextlib.contextmanager
def rig(settings: Settings, progress: Callable[[str], None]) -> Iterator[Path]:
    """A scratch database, a private broker and `settings.workers` Celery workers; yields a workdir."""
    from tests.support.workers import RedisProcess, WorkerProcess

    with contextlib.ExitStack() as stack:
        workdir = Path(stack.enter_context(tempfile.TemporaryDirectory(prefix="hrc-bench-uc-")))
        redis: RedisProcess = RedisProcess(workdir).start()
        stack.callback(redis.stop)
        database_url = stack.enter_context(scratch_database(database_server()))
        progress(f"scratch database {database_url.rsplit('/', 1)[1]}, broker {redis.url}")
        _set_up_django(database_url, redis.url)
        stack.callback(_close_connections)
        environment = {
            "DJANGO_SETTINGS_MODULE": SETTINGS_MODULE,
            "DATABASE_URL": database_url,
            "REDIS_URL": redis.url,
            "HRC_SWEEP_SECONDS": "0.5",
            "HRC_RETRY_BACKOFF": "0.2",
        }
        workers: list[WorkerProcess] = []
        stack.callback(_stop_all, workers)
        for index in range(settings.workers):
            worker = WorkerProcess(
                workdir, name=f"worker{index}", environment=environment, beat=index == 0
            )
            workers.append(worker.start())
        yield workdir


def _stop_all(workers: Sequence[WorkerProcess]) -> None:
    for worker in workers:
        worker.stop()


def _close_connections() -> None:
    from django.db import connections

    connections.close_all()


def measure_use_case(
    path: Path, workdir: Path, settings: Settings, progress: Callable[[str], None]
) -> dict[str, Any]:
    from hrc.cases.simulation import Simulation, case_variants
    from hrc.engine import read_pattern
    from hrc.engine.runtime import CaseNet

    document = json.loads(path.read_text())
    per_round = max(len(case_variants(document, CaseNet(read_pattern(document)))), 1)
    folder = workdir / path.stem
    folder.mkdir()
    cases: list[dict[str, Any]] = []
    with Simulation(
        document, folder, time_scale=settings.time_scale, inline=False, seed=7
    ) as simulation:
        for number in range(settings.rounds):
            progress(f"{path.stem}: round {number + 1} of {settings.rounds} ...")
            with simulation.running():
                ids = simulation.start_cases(per_round)
                ended = simulation.wait(ids, timeout=CASE_TIMEOUT)
            cases += [case_times(case_id) for case_id in ids]
            if not ended:
                break
    return {
        "file": path.name,
        "name": document["name"],
        "pattern": document.get("declared_pattern"),
        "cases_per_round": per_round,
        "summary": summarise(cases),
        "cases": cases,
    }


def run(settings: Settings, progress: Callable[[str], None] = print) -> dict[str, Any]:
    from bench.runtime import machine

    files = use_case_files(settings.only)
    if not files:
        raise SystemExit(f"No use case matches {settings.only} in {USE_CASES_DIR}.")
    load_before = load_average()
    with rig(settings, progress) as workdir:
        host = machine()
        results = [measure_use_case(path, workdir, settings, progress) for path in files]
    report = {
        "benchmark": "use_cases",
        "when": datetime.now(UTC).isoformat(timespec="seconds"),
        "machine": host,
        "load_average": {"before": load_before, "after": load_average()},
        "settings": settings_json(settings),
        "use_cases": results,
    }
    write_results(settings.results_dir, "use-cases", report)
    return report


def print_table(report: Mapping[str, Any]) -> None:
    settings = report["settings"]
    print(
        f"\nUse cases: {settings['rounds']} round(s) each, time scale {settings['time_scale']:g} "
        f"(robot time {1 / settings['time_scale']:g}× faster), {settings['workers']} workers; "
        "medians, wall seconds"
    )
    print(f"{'use case':34} {'cases':>5} {'cycle':>7} {'cobot Σ':>8} {'oper. Σ':>8} "
          f"{'busy':>7} {'idle':>6} {'cycle/busy':>10} {'orch. %':>8} {'ms/task':>8}")  # fmt: skip
    for row in report["use_cases"]:
        s = row["summary"]
        label = row["file"].removesuffix(".json").replace("_", " ")
        cases = f"{s['completed']}/{s['cases']}"
        if not s["completed"]:
            print(f"{label:34} {cases:>5}  no case completed")
            continue
        print(f"{label:34} {cases:>5} {s['cycle_s']:7.2f} {s['cobot_sum_s']:8.2f} "
              f"{s['operator_sum_s']:8.2f} {s['busy_s']:7.2f} {s['idle_s']:6.2f} "
              f"{s['cycle_over_busy']:10.2f} {s['orchestration_share'] * 100:7.1f}% "
              f"{s['idle_ms_per_task']:8.1f}")  # fmt: skip
    print("busy: the time some task of the case ran (the floor for these task times); "
          "idle = cycle − busy: only hrc at work")  # fmt: skip
    print_load(report)


def add_run_options(parser: argparse.ArgumentParser, *, rounds: int) -> None:
    """The options of a bench that runs the use cases (this one, bench.prediction)."""
    parser.add_argument("--time-scale", type=float, help="robot time per wall second (default 0.1)")
    parser.add_argument("--rounds", type=int, help=f"rounds per use case (default {rounds})")
    parser.add_argument("--only", help="use cases by number or file stem, e.g. 2,5_polishing")
    parser.add_argument("--results-dir", type=Path, default=RESULTS_DIR)


def apply_run_options(
    parser: argparse.ArgumentParser,
    arguments: argparse.Namespace,
    settings: Any,
    counts: Sequence[str],
) -> Any:
    """`settings` (a bench's Settings) with add_run_options' options and the `counts` (options
    of at least 1, such as rounds) given; a nonsense value ends the bench with its message."""
    if arguments.time_scale is not None:
        if not 0 < arguments.time_scale <= 1:
            parser.error("--time-scale must be more than 0 and at most 1")
        settings = replace(settings, time_scale=arguments.time_scale)
    for name in counts:
        value = getattr(arguments, name)
        if value is not None:
            if value < 1:
                parser.error(f"--{name} must be at least 1")
            settings = replace(settings, **{name: value})
    if arguments.only:
        only = tuple(part.strip() for part in arguments.only.split(",") if part.strip())
        if not use_case_files(only) or len(use_case_files(only)) < len(only):
            parser.error(f"--only names use cases that do not exist: {arguments.only}")
        settings = replace(settings, only=only)
    return settings


def parse_args(argv: Sequence[str] | None = None) -> Settings:
    parser = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    parser.add_argument("--quick", action="store_true", help=f"a small run: {QUICK}")
    parser.add_argument("--workers", type=int, help=f"Celery workers (default {WORKERS})")
    add_run_options(parser, rounds=Settings.rounds)
    arguments = parser.parse_args(argv)
    settings = replace(Settings(), quick=arguments.quick, results_dir=arguments.results_dir)
    if arguments.quick:
        settings = replace(settings, **QUICK)
    result: Settings = apply_run_options(parser, arguments, settings, ("rounds", "workers"))
    return result


def main(argv: Sequence[str] | None = None) -> None:
    settings = parse_args(argv)
    # Killed politely (a CI timeout), still stop the workers and gateways and drop the database.
    signal.signal(signal.SIGTERM, lambda signum, frame: sys.exit(128 + signum))
    report = run(settings, progress=lambda line: print(line, file=sys.stderr, flush=True))
    print_table(report)
    if any(row["summary"]["completed"] < row["summary"]["cases"] for row in report["use_cases"]):
        sys.exit(1)


if __name__ == "__main__":
    main()
