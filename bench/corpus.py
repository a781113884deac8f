"""`make bench`: importing and checking the shared corpus of other tools' models, against a floor.

Every BPMN and PNML file of `../shared/corpus/` (or `--corpus`) goes through its importer
(`bpmn_to_pattern`, `pnml_to_pattern`) and, when it imports, the whole check
(`check_pattern`). The floor, measured in the same run, is parsing the same bytes with
ElementTree alone: no importer can read a file faster than its XML parser. Each file is
timed best of `--runs`; the table gives the whole corpus, BPMN and PNML apart, and the
largest imported model (most places and transitions) with its name. Results go to
`bench/results/corpus-<UTC>.json` and `corpus-latest.json`.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import sys
import time
import xml.etree.ElementTree as ET
from collections.abc import Callable
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

from bench.report import load_average, print_load, write_results
from bench.run import machine
from hrc.engine.bpmn import bpmn_to_pattern
from hrc.engine.check import check_pattern
from hrc.engine.document import FormatError
from hrc.engine.model import Pattern
from hrc.engine.pnml import pnml_to_pattern

ROOT = Path(__file__).resolve().parent.parent
CORPUS = Path(os.environ.get("HRC_CORPUS") or ROOT.parent / "shared" / "corpus")
RESULTS_DIR = Path(__file__).resolve().parent / "results"
IMPORTERS: dict[str, Callable[[bytes], Pattern]] = {
    ".bpmn": bpmn_to_pattern,
    ".pnml": pnml_to_pattern,
}


def best_ms(work: Callable[[], object], runs: int) -> float:
    """The fastest of `runs` calls, in milliseconds."""
    fastest = float("inf")
    for _ in range(runs):
        started = time.perf_counter()
        work()
        fastest = min(fastest, time.perf_counter() - started)
    return fastest * 1000


def measure_file(path: Path, runs: int) -> dict[str, Any]:
    """One file: floor, import and check times, and what became of it."""
    text = path.read_bytes()
    read = IMPORTERS[path.suffix]
    row: dict[str, Any] = {
        "file": f"{path.parent.name}/{path.name}",
        "kind": path.suffix[1:],
        "bytes": len(text),
        "floor_ms": best_ms(lambda: ET.fromstring(text), runs),
        "import_ms": best_ms(lambda: _import(read, text), runs),
    }
    try:
        pattern = read(text)
    except FormatError as refusal:
        return row | {"imported": False, "issues": len(refusal.issues), "check_ms": 0.0}
    report = check_pattern(pattern)
    row |= {
        "imported": True,
        "nodes": sum(len(p.places) + len(p.transitions) for p in pattern.processes),
        "sound": report.sound,
        "markings": report.stats.get("markings"),
        "check_ms": best_ms(lambda: check_pattern(pattern), runs),
    }
    return row


def _import(read: Callable[[bytes], Pattern], text: bytes) -> None:
    with contextlib.suppress(FormatError):  # a refusal is timed as an import
        read(text)


def summary(rows: list[dict[str, Any]]) -> dict[str, Any]:
    floor = sum(row["floor_ms"] for row in rows)
    total = sum(row["import_ms"] + row["check_ms"] for row in rows)
    return {
        "files": len(rows),
        "imported": sum(1 for row in rows if row["imported"]),
        "floor_ms": round(floor, 3),
        "import_ms": round(sum(row["import_ms"] for row in rows), 3),
        "check_ms": round(sum(row["check_ms"] for row in rows), 3),
        "total_ms": round(total, 3),
        "ratio_to_floor": round(total / floor, 1) if floor else None,
    }


def run(corpus: Path, runs: int, results_dir: Path) -> dict[str, Any]:
    """Measures every file of `corpus`; raises FileNotFoundError when it holds none."""
    files = sorted(path for path in corpus.glob("*/*") if path.suffix in IMPORTERS)
    if not files:
        raise FileNotFoundError(f"no .bpmn or .pnml files under {corpus}/*/")
    load_before = load_average()
    rows = [measure_file(path, runs) for path in files]
    imported = [row for row in rows if row["imported"]]
    largest = max(imported, key=lambda row: (row["nodes"], row["bytes"]), default=None)
    report: dict[str, Any] = {
        "benchmark": "corpus",
        "when": datetime.now(UTC).isoformat(timespec="seconds"),
        "machine": machine(),
        "load_average": {"before": load_before, "after": load_average()},
        "corpus": str(corpus),
        "runs": runs,
        "whole": summary(rows),
        "bpmn": summary([row for row in rows if row["kind"] == "bpmn"]),
        "pnml": summary([row for row in rows if row["kind"] == "pnml"]),
        "largest": largest and largest | summary([largest]),
        "files": rows,
    }
    write_results(results_dir, "corpus", report)
    return report


def print_table(report: dict[str, Any]) -> None:
    print(
        f"\nCorpus import and check: {report['whole']['files']} files, best of {report['runs']} "
        "each (floor: ElementTree parsing the same bytes)"
    )
    header = ("", "files", "imported", "floor ms", "import ms", "check ms", "total ms", "/floor")
    print(f"{header[0]:28} " + " ".join(f"{cell:>9}" for cell in header[1:]))
    rows = [("whole corpus", report["whole"]), ("BPMN", report["bpmn"]), ("PNML", report["pnml"])]
    if report["largest"]:
        rows.append(("largest model (below)", report["largest"]))
    for label, row in rows:
        cells = [
            str(row["files"]),
            str(row["imported"]),
            *(f"{row[key]:.2f}" for key in ("floor_ms", "import_ms", "check_ms", "total_ms")),
            f"{row['ratio_to_floor']:.1f}" if row["ratio_to_floor"] else "-",
        ]
        print(f"{label:28} " + " ".join(f"{cell:>9}" for cell in cells))
    largest = report["largest"]
    if largest:
        verdict = {True: "sound", False: "unsound", None: "soundness undecided"}[largest["sound"]]
        explored = f", {largest['markings']} markings" if largest["markings"] is not None else ""
        print(
            f"largest model: {largest['file']} ({largest['nodes']} places and transitions, "
            f"{largest['bytes'] / 1024:.0f} KiB; {verdict}{explored})"
        )
    print_load(report)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--corpus", type=Path, default=CORPUS, help=f"default {CORPUS}")
    parser.add_argument("--runs", type=int, default=5, help="timed runs per file (default 5)")
    parser.add_argument("--results-dir", type=Path, default=RESULTS_DIR)
    arguments = parser.parse_args()
    if arguments.runs < 1:
        parser.error("--runs must be at least 1")
    try:
        report = run(arguments.corpus, arguments.runs, arguments.results_dir)
    except FileNotFoundError as missing:
        sys.exit(f"The corpus is missing: {missing}. Check out ../shared, or pass --corpus.")
    print_table(report)


if __name__ == "__main__":
    main()
