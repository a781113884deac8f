"""`manage.py predict FILE [--cases N] [--parallel P] [--seed S] [--people o=2 ...] [--json]`:
predicts an `hrc-pattern/1` file by simulation (hrc.patterns.prediction), as
POST /api/patterns/predict/ does, without measured times (a file belongs to no pattern).

Prints a table (cycle time, throughput, each actor's load, the bottleneck, the typical
case's critical path), or with --json the API's answer. Exit status 2, with a message,
for a usage error or a file that cannot be read, is not a document, breaks a structural
rule or names what it does not have. Reads files only: it needs no database.
"""

import json
from typing import Any

from django.core.management.base import BaseCommand, CommandError, CommandParser

from hrc.engine.document import FormatError, parse_json
from hrc.errors import Refusal
from hrc.patterns.prediction import MAX_CASES, MAX_PARALLEL, Options, Predicted, predict_document

EXIT_USAGE = 2


def bounded(low: int, high: int) -> Any:
    """An argparse type: a whole number in [low, high]."""

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise ValueError(text) from None
        if not low <= value <= high:
            raise ValueError(text)
        return value

    parse.__name__ = f"whole number from {low} to {high}"
    return parse


def team(text: str) -> tuple[str, int]:
    """`o=2`: the operator actor o is a team of two."""
    actor, _, persons = text.partition("=")
    if not actor or not persons.isdigit() or int(persons) < 1:
        raise ValueError(text)
    return actor, int(persons)


team.__name__ = "ACTOR=PERSONS (persons ≥ 1)"


def describe(predicted: Predicted) -> list[str]:
    """The lines a person reads."""
    p = predicted.prediction
    lines = [f"{p.completed} of {p.cases} cases completed, {p.parallel} at a time (seed {p.seed})"]
    if p.cycle_time is not None:
        c = p.cycle_time
        lines.append(f"cycle time  p50 {c.p50:.1f} s · p90 {c.p90:.1f} s · p99 {c.p99:.1f} s")
    lines.append(f"throughput  {p.throughput_per_hour:.1f} cases per hour")
    lines += ["", f"{'actor':<20} {'kind':<9} {'utilisation':>11} {'waiting/case':>13}"]
    for load in p.actors:
        lines.append(
            f"{load.actor:<20} {load.kind:<9} {load.utilisation:>10.0%} "
            f"{load.waiting_per_case:>11.1f} s"
        )
    if p.bottleneck is not None:
        bottleneck = p.task(p.bottleneck)
        lines += ["", f"bottleneck  {bottleneck.label} ({bottleneck.task}, {bottleneck.actor}): "
                  f"{bottleneck.critical_share:.0%} of the cycle"]  # fmt: skip
    lines += ["", "critical path of the typical case:"]
    for step in p.critical_path:
        lines.append(
            f"  {step.started:>8.1f} s  {step.label} ({step.actor}): "
            f"waited {step.waited:.1f} s, worked {step.worked:.1f} s"
        )
    lines += ["", "task times:"]
    for task, time in predicted.times.items():
        lines.append(f"  {task}: {time.source}, {time.describe()}")
    if p.stuck_count:
        lines += ["", f"{p.stuck_count} cases could not end; the first: {p.stuck[0].why}"]
    return lines


class Command(BaseCommand):
    help = "Predicts an hrc-pattern/1 file by simulating many cases."

    # A prediction of a file touches no database, so neither checks nor migrations may stop it.
    requires_system_checks: list[str] = []
    requires_migrations_checks = False

    def add_arguments(self, parser: CommandParser) -> None:
        parser.add_argument("file", metavar="FILE", help="an hrc-pattern/1 JSON file")
        parser.add_argument("--cases", type=bounded(1, MAX_CASES), default=1000)
        parser.add_argument("--parallel", type=bounded(1, MAX_PARALLEL), default=1)
        parser.add_argument("--seed", type=bounded(0, 2**63 - 1), default=0)
        parser.add_argument(
            "--people", type=team, nargs="+", default=[], metavar="ACTOR=PERSONS",
            help="operator teams: --people o=2 o2=3",
        )  # fmt: skip
        parser.add_argument("--json", action="store_true", help="print the API's answer")

    def handle(self, *args: Any, **options: Any) -> None:
        path = options["file"]
        try:
            with open(path, "rb") as file:
                document = parse_json(file.read())
            predicted = predict_document(
                document,
                Options(
                    cases=options["cases"],
                    parallel=options["parallel"],
                    seed=options["seed"],
                    people=dict(options["people"]),
                ),
            )
        except OSError as exc:
            message = f"{path}: cannot read the file: {exc.strerror or exc}"
            raise CommandError(message, returncode=EXIT_USAGE) from None
        except FormatError as exc:
            message = f"{path}: not a readable hrc-pattern/1 document: {exc}"
            raise CommandError(message, returncode=EXIT_USAGE) from None
        except Refusal as exc:
            raise CommandError(f"{path}: {exc}", returncode=EXIT_USAGE) from None
        if options["json"]:
            self.stdout.write(json.dumps(predicted.as_dict(), ensure_ascii=False))
        else:
            for line in describe(predicted):
                self.stdout.write(line)
