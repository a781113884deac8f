"""`python manage.py run_pattern FILE [--cases N] --simulate [--time-scale F] [--durations FILE] --json`

Runs a pattern file end to end against simulated cobots (one OPC UA gateway
process per cobot actor) with operators that complete their tasks by
themselves, and prints one JSON event per line:
{"seq", "at", "case", "task", "actor", "event"}. Exits 0 when every case completed.
How simulated operators fill forms, and how a document's cases may differ
(`"simulation": {"cases": [...]}`), is in hrc/cases/simulation.py. `--durations` gives
operator tasks' times as distributions, the prediction's (hrc.engine.durations): a JSON
object of task id → {"kind": "triangular", "low": 20, "mode": 25, "high": 40} and the like.
"""

from __future__ import annotations

import json
import signal
import tempfile
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from types import FrameType
from typing import Any, NoReturn

from django.core.management.base import BaseCommand, CommandError, CommandParser

from hrc.cases.simulation import Simulation, case_variants
from hrc.database import ensure_migrated
from hrc.engine.check import check_document
from hrc.engine.document import FormatError, parse_json, read_pattern
from hrc.engine.durations import Duration, DurationError, duration_from_dict
from hrc.engine.model import Pattern
from hrc.engine.runtime import CaseNet


class Command(BaseCommand):
    help = "Runs a pattern's cases against simulated cobots and prints what happened."

    def add_arguments(self, parser: CommandParser) -> None:
        parser.add_argument("file", type=Path, help="An hrc-pattern/1 document.")
        parser.add_argument("--cases", type=int, default=1, help="How many cases to run.")
        parser.add_argument(
            "--simulate", action="store_true", required=True,
            help="Simulated cobots and operators (the only mode: real ones run from the tablets).",
        )  # fmt: skip
        parser.add_argument(
            "--time-scale", type=float, default=0.05,
            help="Simulated time per real second (steps, operators and timers): 0.05 runs twenty "
            "times faster, 0 takes no time.",
        )  # fmt: skip
        parser.add_argument(
            "--timer-scale", type=float, default=None,
            help="Simulated time per real second for timers alone (default: --time-scale): "
            "a model whose timers wait hours runs in seconds.",
        )  # fmt: skip
        parser.add_argument("--json", action="store_true", help="One JSON event per line.")
        parser.add_argument("--timeout", type=float, default=600.0, help="Give up after (s).")
        parser.add_argument(
            "--workers", choices=("inline", "celery"), default="inline",
            help="inline: jobs run on threads here; celery: on workers started separately.",
        )  # fmt: skip
        parser.add_argument("--seed", type=int, default=None, help="Operators' random delays.")
        parser.add_argument(
            "--durations", type=Path, default=None,
            help="JSON: operator task id → its time as a distribution ({\"kind\": \"fixed\", "
            "\"seconds\": 20}, triangular, lognormal, empirical), simulated seconds; other "
            "operator tasks take 0.2–1.0 s.",
        )  # fmt: skip

    def handle(self, *args: Any, **options: Any) -> None:
        document = self._read(options["file"])
        durations = {}
        if options["durations"] is not None:
            durations = _read_durations(options["durations"], read_pattern(document))
        if options["cases"] < 1:
            raise CommandError("--cases must be 1 or more.")
        if options["time_scale"] < 0:
            raise CommandError("--time-scale must be 0 or more.")
        if options["timer_scale"] is not None and options["timer_scale"] < 0:
            raise CommandError("--timer-scale must be 0 or more.")
        # Its cases live in a scratch organisation, so right after cloning it may create and
        # migrate the embedded SQLite itself; a PostgreSQL database it only reports.
        ensure_migrated(migrate_sqlite=True)
        with (
            _exit_on_sigterm(),
            tempfile.TemporaryDirectory(prefix="hrc-run-pattern-") as workdir,
            Simulation(
                document, Path(workdir), time_scale=options["time_scale"],
                timer_scale=options["timer_scale"],
                inline=options["workers"] == "inline", seed=options["seed"],
                durations=durations,
            ) as simulation,
        ):  # fmt: skip
            events = simulation.run(options["cases"], timeout=options["timeout"])
        for event in events:
            if options["json"]:
                self.stdout.write(json.dumps(event.as_dict()))
            else:
                self.stdout.write(
                    f"{event.seq:5} {event.at} case {event.case} "
                    f"{event.event} {event.task or ''} {event.actor or ''}".rstrip()
                )
        failed = sorted({e.case for e in events if e.event == "case-failed"})
        if failed:
            raise CommandError(f"{len(failed)} case(s) did not complete: {failed}")

    def _read(self, path: Path) -> dict[str, Any]:
        try:
            text = path.read_bytes()
        except OSError as error:
            raise CommandError(f"Cannot read {path}: {error.strerror}.") from None
        try:
            data = parse_json(text)
        except FormatError as error:
            raise CommandError(f"{path}: {error}") from None
        report = check_document(data)
        if not report.valid or not isinstance(data, dict):
            problems = "; ".join(f"{issue.code}: {issue.message}" for issue in report.errors)
            raise CommandError(f"{path} cannot run: {problems}")
        try:
            case_variants(data, CaseNet(read_pattern(data)))
        except ValueError as error:
            raise CommandError(f"{path} cannot run: {error}") from None
        return data


def _read_durations(path: Path, pattern: Pattern) -> dict[str, Duration]:
    """Operator task id → its time, from a JSON file; CommandError saying what is wrong."""
    try:
        data = json.loads(path.read_bytes())
    except OSError as error:
        raise CommandError(f"Cannot read {path}: {error.strerror}.") from None
    except ValueError as error:
        raise CommandError(f"{path} is not JSON: {error}") from None
    if not isinstance(data, dict):
        raise CommandError(f"{path} must be an object of task id → time.")
    durations = {}
    for task, time in data.items():
        transition = pattern.transition(task)
        actor = pattern.actor(transition.performer) if transition and transition.performer else None
        if actor is None or actor.type != "operator":
            raise CommandError(f"{path}: {task!r} is not an operator's task of the pattern.")
        try:
            durations[task] = duration_from_dict(time if isinstance(time, dict) else {})
        except DurationError as error:
            raise CommandError(f"{path}: {task}: {error}") from None
    return durations


@contextmanager
def _exit_on_sigterm() -> Iterator[None]:
    """SIGTERM (a test's or a supervisor's stop) unwinds like Ctrl-C, so the simulation stops
    its gateway processes; Python's default ends at once and leaves them running."""
    if threading.current_thread() is not threading.main_thread():
        yield  # signal handlers can only be set from the main thread (call_command elsewhere)
        return

    def leave(signum: int, frame: FrameType | None) -> NoReturn:
        raise SystemExit(128 + signum)

    previous = signal.signal(signal.SIGTERM, leave)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)
