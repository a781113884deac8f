"""What every bench's report shares: where it is written, and the machine's load beside it."""

from __future__ import annotations

import json
import os
from collections.abc import Mapping
from dataclasses import asdict
from datetime import UTC, datetime
from pathlib import Path
from typing import Any


def load_average() -> list[float] | None:
    """The 1, 5 and 15 minute load averages, where the system has them."""
    try:
        return [round(value, 2) for value in os.getloadavg()]
    except OSError:
        return None


def settings_json(settings: Any) -> dict[str, Any]:
    """A bench's settings (a dataclass) as its report records them: tuples as lists, without
    where the results go."""
    return {
        key: list(value) if isinstance(value, tuple) else value
        for key, value in asdict(settings).items()
        if key != "results_dir"
    }


def write_results(results_dir: Path, name: str, report: Mapping[str, Any]) -> None:
    """`<name>-<UTC>.json` (kept) and `<name>-latest.json` (replaced) under `results_dir`."""
    results_dir.mkdir(parents=True, exist_ok=True)
    stamp = datetime.now(UTC).strftime("%Y%m%dT%H%M%SZ")
    text = json.dumps(report, indent=2) + "\n"
    for file in (f"{name}-{stamp}.json", f"{name}-latest.json"):
        (results_dir / file).write_text(text)


def print_load(report: Mapping[str, Any]) -> None:
    """The table's last line: the load when the run began (report["load_average"]["before"])."""
    load, cores = report["load_average"]["before"], report["machine"]["cpu_count"]
    if load:
        print(f"load average {load[0]:.2f} on {cores} cores at the start; compare quiet runs only")
