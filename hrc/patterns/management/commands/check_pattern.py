"""`manage.py check_pattern FILE... [--json]`: checks `hrc-pattern/1` files with the engine.

Exit status: 0 when every file is valid, 1 when any is not (a file that is
not JSON or not the format counts as invalid, code `format`), 2 for a usage
error or a file that cannot be read; the others are still checked and
reported. The command reads files only: it needs no database.
"""

import json
from dataclasses import dataclass
from typing import Any

from django.core.management.base import BaseCommand, CommandParser

from hrc.engine import check_document
from hrc.engine.document import FormatError, parse_json
from hrc.engine.issues import Issue

EXIT_VALID = 0
EXIT_INVALID = 1
EXIT_USAGE = 2  # argparse's own status for a usage error; an unreadable file is one too


@dataclass(frozen=True)
class FileCheck:
    """What the command reports for one file."""

    path: str
    valid: bool
    patterns: tuple[str, ...]
    sound: bool | None
    errors: tuple[Issue, ...]
    warnings: tuple[Issue, ...]

    @classmethod
    def not_the_format(cls, path: str, issues: list[Issue]) -> "FileCheck":
        return cls(path, False, (), None, tuple(issues), ())

    def as_json(self) -> dict[str, Any]:
        return {
            "path": self.path,
            "valid": self.valid,
            "patterns": list(self.patterns),
            "sound": self.sound,
            "errors": [_issue_json(issue) for issue in self.errors],
            "warnings": [_issue_json(issue) for issue in self.warnings],
        }


def check_file_content(path: str, content: bytes) -> FileCheck:
    """Checks the bytes of one file; never raises for a bad document."""
    try:
        data = parse_json(content)
    except FormatError as exc:
        return FileCheck.not_the_format(path, exc.issues)
    try:
        report = check_document(data)
    except FormatError as exc:
        # The engine reports shape problems in the report; this keeps a reader
        # that raises instead from ending the run with a traceback.
        return FileCheck.not_the_format(path, exc.issues)
    return FileCheck(
        path=path,
        valid=report.valid,
        patterns=tuple(report.patterns),
        sound=report.sound,
        errors=tuple(report.errors),
        warnings=tuple(report.warnings),
    )


def describe(check: FileCheck) -> list[str]:
    """The lines a person reads for one file: a headline, then one entry per issue."""
    lines = [f"{check.path}: {_headline(check)}"]
    for issue in (*check.errors, *check.warnings):
        lines.extend(_issue_lines(issue))
    return lines


def _headline(check: FileCheck) -> str:
    if not check.valid:
        return "INVALID"
    patterns = ", ".join(check.patterns) or "no pattern"
    soundness = {True: "sound", False: "unsound", None: "soundness not checked"}[check.sound]
    return f"valid · {patterns} · {soundness}"


def _issue_lines(issue: Issue) -> list[str]:
    line = f"  {issue.severity} [{issue.code}] {issue.message}"
    if issue.elements:
        line += f" (elements: {', '.join(issue.elements)})"
    if issue.witness is None:
        return [line]
    return [line, f"    firing sequence: {' → '.join(issue.witness) or '(none)'}"]


def _issue_json(issue: Issue) -> dict[str, Any]:
    return {"code": issue.code, "message": issue.message, "elements": list(issue.elements)}


class Command(BaseCommand):
    help = "Checks hrc-pattern/1 files: rules, pattern classification and soundness."

    # A file check touches no database, so neither checks nor migrations may stop it.
    requires_system_checks: list[str] = []
    requires_migrations_checks = False

    def add_arguments(self, parser: CommandParser) -> None:
        # nargs="+" makes "no files" a usage error, which argparse ends with status 2.
        parser.add_argument("files", nargs="+", metavar="FILE", help="hrc-pattern/1 JSON files")
        parser.add_argument(
            "--json", action="store_true", help="print one JSON object per file, one per line"
        )

    def handle(self, *args: Any, **options: Any) -> None:
        status = EXIT_VALID
        for path in options["files"]:
            try:
                with open(path, "rb") as file:
                    content = file.read()
            except OSError as exc:
                self.stderr.write(f"{path}: cannot read the file: {exc.strerror or exc}")
                status = EXIT_USAGE
                continue
            check = check_file_content(path, content)
            self._report(check, as_json=options["json"])
            if not check.valid and status == EXIT_VALID:
                status = EXIT_INVALID
        if status != EXIT_VALID:
            raise SystemExit(status)

    def _report(self, check: FileCheck, *, as_json: bool) -> None:
        if as_json:
            self.stdout.write(json.dumps(check.as_json(), ensure_ascii=False))
        else:
            for line in describe(check):
                self.stdout.write(line)
