"""The controller's saved state: one JSON file, replaced atomically.

A real controller keeps its registers, program and position when the
gateway in front of it restarts; the simulator is both, so it writes what a
controller would keep to `state_file` at every step lifecycle point and
every command, and reads it back on start.

The file is replaced atomically (write, then rename) but not fsync'ed: it
survives the gateway process being killed, which is what the simulator has to
stand in for, and a step stays in the millisecond range (an fsync per
lifecycle point would not). A power cut may lose the last writes.

Next to it the step log (`read_step_log`) keeps each step that ran: when it
started and ended and at what speed override, for tests that check what the
cobots did (two sharing an area never at once, a step slowed for an operator).
"""

from __future__ import annotations

import json
import logging
import os
import tempfile
import threading
from pathlib import Path
from typing import Any, Final

logger = logging.getLogger(__name__)

FORMAT: Final = 1


def step_log_path(state_file: Path) -> Path:
    """The step log next to a state file: one JSON line per step that ran (token, step, program,
    started and ended in Unix seconds, the speed override at its start, lowest and end)."""
    return state_file.with_name(state_file.name + ".steps")


def read_step_log(state_file: Path) -> list[dict[str, Any]]:
    """The steps the simulator at `state_file` ran, in order; a torn last line is dropped."""
    try:
        lines = step_log_path(state_file).read_text(encoding="utf-8").splitlines()
    except FileNotFoundError:
        return []
    steps = []
    for line in lines:
        try:
            steps.append(json.loads(line))
        except json.JSONDecodeError:
            break
    return steps


class CorruptState(ValueError):
    """The state file exists but holds no state this simulator can read."""


class StateFile:
    """Saves and loads the simulator's state at `path`.

    Saves run in a worker thread so the event loop keeps serving; they are
    numbered in call order, and one that would land after a newer one is
    skipped, so the file never goes back in time (even when the coroutine
    that asked for a save was cancelled while its thread ran on).
    """

    def __init__(self, path: Path) -> None:
        self.path = path
        # The execution log's journal, one "step_id attempt ran" line per token judged.
        self.journal_path = path.with_name(path.name + ".journal")
        # The steps that ran, one JSON object a line: when, and at what speed override.
        self.steps_path = step_log_path(path)
        self._lock = threading.Lock()
        self._requested = 0
        self._written = 0
        self.journal_lines = 0

    def load_journal(self) -> list[list[int]]:
        """The journal's entries; a torn last line (a kill mid-append) is dropped."""
        try:
            lines = self.journal_path.read_text(encoding="utf-8").splitlines()
        except FileNotFoundError:
            return []
        except (OSError, UnicodeDecodeError) as error:
            raise CorruptState(f"cannot read {self.journal_path}: {error}") from error
        entries = []
        for number, line in enumerate(lines, 1):
            fields = line.split()
            if len(fields) != 3 or not all(f.lstrip("-").isdigit() for f in fields):
                if number == len(lines):
                    logger.warning("%s: dropping a torn last line", self.journal_path)
                    break
                raise CorruptState(f"{self.journal_path} line {number} is not 'id attempt ran'")
            entries.append([int(f) for f in fields])
        self.journal_lines = len(entries)
        return entries

    def append_journal(self, entries: list[list[int]]) -> None:
        """Appends entries (before the snapshot that counts them is saved)."""
        self.journal_path.parent.mkdir(parents=True, exist_ok=True)
        with self.journal_path.open("a", encoding="utf-8") as journal:
            journal.write("".join(f"{a} {b} {c}\n" for a, b, c in entries))
        self.journal_lines += len(entries)

    def rewrite_journal(self, entries: list[list[int]]) -> None:
        """Replaces the journal atomically by `entries` (compaction, or a fresh start)."""
        self.journal_path.parent.mkdir(parents=True, exist_ok=True)
        tmp = self.journal_path.with_name(self.journal_path.name + ".tmp")
        tmp.write_text("".join(f"{a} {b} {c}\n" for a, b, c in entries), encoding="utf-8")
        os.replace(tmp, self.journal_path)
        self.journal_lines = len(entries)

    def append_step(self, record: dict[str, Any]) -> None:
        """Appends a step that ran to the step log (what a test reads; nothing reads it back)."""
        self.steps_path.parent.mkdir(parents=True, exist_ok=True)
        with self.steps_path.open("a", encoding="utf-8") as steps:
            steps.write(json.dumps(record, sort_keys=True) + "\n")

    def load(self) -> dict[str, Any] | None:
        """The saved state; None when there is no file; CorruptState when it can't be read."""
        try:
            text = self.path.read_text(encoding="utf-8")
        except FileNotFoundError:
            return None
        except (OSError, UnicodeDecodeError) as error:
            raise CorruptState(f"cannot read {self.path}: {error}") from error
        try:
            data = json.loads(text)
        except (json.JSONDecodeError, RecursionError) as error:  # the latter: nested too deep
            raise CorruptState(f"{self.path} is not JSON: {error}") from error
        if not isinstance(data, dict) or data.get("format") != FORMAT:
            raise CorruptState(f"{self.path} is not a format-{FORMAT} simulator state")
        return data

    def set_aside(self) -> Path | None:
        """Renames an unreadable file to `<name>.corrupt` (kept for a post-mortem)."""
        aside = self.path.with_name(self.path.name + ".corrupt")
        try:
            self.path.replace(aside)
        except OSError:
            return None
        return aside

    async def save(self, state: dict[str, Any]) -> None:
        """Writes `state` (a fresh JSON-able dict) durably; returns once it is on disk."""
        self._requested += 1
        # In the loop, not a thread: a small local write takes less than a thread hop.
        self._write(self._requested, {"format": FORMAT, **state})

    def _write(self, number: int, state: dict[str, Any]) -> None:
        with self._lock:
            if number <= self._written:
                return
            text = json.dumps(state, separators=(",", ":"))
            directory = self.path.parent
            directory.mkdir(parents=True, exist_ok=True)
            fd, tmp = tempfile.mkstemp(prefix=f".{self.path.name}.", dir=directory)
            try:
                with os.fdopen(fd, "w", encoding="utf-8") as file:
                    file.write(text)
                os.replace(tmp, self.path)
            except BaseException:
                Path(tmp).unlink(missing_ok=True)
                raise
            self._written = number
