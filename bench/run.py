"""`make bench`: time our soundness check against pm4py's Woflan on generated nets.

For every family of bench/nets.py at every size this measures, in one run on
one machine:

- the floor: `json.loads` + `read_pattern` of the document, the work any
  checker must do before it can look at the model;
- ours: `check_document(json.loads(text))`, best of N in this process, and
  its peak traced memory in a separate run (tracemalloc slows the run it
  watches, so it is never the timed one);
- Woflan (pm4py) on the same execution net, in a child process with a time
  limit (bench/woflan.py).

Results go to bench/results/soundness-<UTC timestamp>.json and
bench/results/soundness-latest.json; a table goes to stdout. See bench/README.md.
"""

import argparse
import gc
import json
import os
import platform
import signal
import subprocess
import sys
import threading
import time
import tracemalloc
from collections.abc import Callable, Iterator, Mapping, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from datetime import UTC, datetime
from importlib import metadata
from pathlib import Path
from typing import Any

from bench.nets import EXPECTED_SOUND, FAMILIES, SIZES, generate, transition_count
from bench.report import load_average
from hrc.engine import check_document
from hrc.engine.document import read_pattern
from hrc.engine.execution import build_execution_net

RESULTS_DIR = Path(__file__).resolve().parent / "results"
SLOW_SECONDS = 1.0
"""The target: every net decided in under a second."""
DEFAULT_RUNS = 5
FLOOR_RUNS = 20
"""The floor is tens of microseconds at 20 transitions; more runs steady its minimum."""


class CheckTimeout(BaseException):
    """Raised into a check that overran its guard.

    A BaseException, not an Exception, so that no `except Exception` inside
    the engine can swallow it.
    """


@contextmanager
def _guard(seconds: float) -> Iterator[None]:
    """Interrupt the body after `seconds` so that `make bench` always ends by itself.

    Our check runs in this process (so its time and memory are ours alone);
    a SIGALRM timer bounds it in case a change makes it explode. Only the
    main thread receives signals, so elsewhere the body runs unguarded.
    """
    if threading.current_thread() is not threading.main_thread() or seconds <= 0:
        yield
        return

    def expire(signum: int, frame: object) -> None:
        raise CheckTimeout

    previous = signal.signal(signal.SIGALRM, expire)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)


def _best_time(run: Callable[[], object], runs: int, enough: float) -> tuple[float, int]:
    """The fastest of up to `runs` runs, stopping early once one takes `enough` seconds.

    The minimum is the run least disturbed by the rest of the machine; a
    slow net is not repeated, so the whole benchmark stays bounded.
    """
    best = float("inf")
    done = 0
    for _ in range(runs):
        gc.collect()
        began = time.perf_counter()
        run()
        seconds = time.perf_counter() - began
        best = min(best, seconds)
        done += 1
        if seconds >= enough:
            break
    return best, done


def _peak_memory(run: Callable[[], object]) -> int:
    """Peak bytes allocated by Python during one run (tracemalloc)."""
    gc.collect()
    tracemalloc.start()
    try:
        run()
        return tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


def _markings(stats: Mapping[str, int]) -> int | None:
    """The number of markings explored, whatever the engine calls the counter."""
    if "markings" in stats:
        return stats["markings"]
    for key, value in stats.items():
        if "marking" in key:
            return value
    return None


@dataclass
class Settings:
    families: list[str]
    sizes: list[int]
    runs: int
    woflan: bool
    woflan_timeout: float
    check_timeout: float
    results_dir: Path


def measure(family: str, size: int, settings: Settings, woflan_skip: str | None) -> dict[str, Any]:
    """Everything recorded for one net."""
    document = generate(family, size)
    text = json.dumps(document)
    net = build_execution_net(read_pattern(document))

    floor, _ = _best_time(
        lambda: read_pattern(json.loads(text)), max(FLOOR_RUNS, settings.runs), SLOW_SECONDS
    )

    row: dict[str, Any] = {
        "family": family,
        "transitions": transition_count(document),
        "constraints": len(document["constraints"]),
        "expected_sound": EXPECTED_SOUND[family],
        "execution_net": {
            "places": len(net.places),
            "transitions": len(net.transitions),
            "constraint_places": len(net.ignored),
        },
        "floor_seconds": floor,
    }

    reports: list[Any] = []

    def ours() -> None:
        with _guard(settings.check_timeout):
            reports.append(check_document(json.loads(text)))

    try:
        seconds, runs = _best_time(ours, settings.runs, SLOW_SECONDS)
    except CheckTimeout:
        row["ours"] = {"seconds": None, "timed_out": True, "timeout": settings.check_timeout}
    except Exception as exc:
        # An engine bug on one net is a finding, not a reason to lose the other nets' numbers.
        row["ours"] = {"seconds": None, "timed_out": False, "error": f"{type(exc).__name__}: {exc}"}
    else:
        peak: int | None
        try:
            # tracemalloc makes the run several times slower; if that overruns
            # the guard the memory is unknown, the time above still stands.
            with _guard(settings.check_timeout):
                peak = _peak_memory(lambda: check_document(json.loads(text)))
        except CheckTimeout:
            peak = None
        report = reports[-1]
        errors = list(report.errors)
        unsound = [issue for issue in errors if issue.code in ("unsound", "unbounded")]
        stats = dict(report.stats)
        row["ours"] = {
            "seconds": seconds,
            "runs": runs,
            "timed_out": False,
            "peak_memory_bytes": peak,
            "sound": report.sound,
            "error_codes": sorted({issue.code for issue in errors}),
            "witness": any(issue.witness for issue in unsound) if unsound else None,
            "witness_length": next((len(i.witness) for i in unsound if i.witness), None),
            "markings": _markings(stats),
            "stats": stats,
        }
        row["ratio_to_floor"] = seconds / floor if floor > 0 else None

    row["woflan"] = _woflan(net, settings, woflan_skip)
    row["ratio_to_woflan"] = _ratio_to_woflan(row)
    row["flags"] = _flags(row)
    return row


def _woflan(net: Any, settings: Settings, skip: str | None) -> dict[str, Any] | None:
    if not settings.woflan:
        return None
    if skip is not None:
        # A smaller net of the same family already overran the limit; a larger
        # one only takes longer, so do not spend another limit on it.
        return {
            "seconds": None,
            "sound": None,
            "timed_out": True,
            "timeout": settings.woflan_timeout,
            "skipped": skip,
        }
    # Imported here so that `--no-woflan` (and the tests) never start pm4py's machinery.
    from bench.woflan import net_spec, run_woflan

    result = run_woflan(net_spec(net), settings.woflan_timeout)
    return {
        "seconds": result.seconds,
        "sound": result.sound,
        "timed_out": result.timed_out,
        "timeout": settings.woflan_timeout,
        "error": result.error,
    }


def _ratio_to_woflan(row: Mapping[str, Any]) -> float | None:
    ours, woflan = row["ours"].get("seconds"), row["woflan"]
    if ours is None or woflan is None:
        return None
    if woflan["seconds"] is not None and woflan["seconds"] > 0:
        return float(ours / woflan["seconds"])
    return None


def _flags(row: Mapping[str, Any]) -> list[str]:
    """What a reader must look at; the table prints them and the JSON keeps them."""
    flags = []
    ours, woflan = row["ours"], row["woflan"]
    if ours.get("error"):
        flags.append("ENGINE-ERROR")
        return flags + (["WOFLAN-ERROR"] if woflan is not None and woflan.get("error") else [])
    if ours["timed_out"] or (ours["seconds"] is not None and ours["seconds"] >= SLOW_SECONDS):
        flags.append("SLOW")
    if not ours["timed_out"]:
        if ours["sound"] is None:
            flags.append("UNDECIDED")
        elif ours["sound"] != row["expected_sound"]:
            flags.append("UNEXPECTED")
        if ours["sound"] is False and not ours["witness"]:
            flags.append("NO-WITNESS")
    if woflan is not None:
        if (
            woflan["sound"] is not None
            and not ours["timed_out"]
            and ours["sound"] is not None
            and woflan["sound"] != ours["sound"]
        ):
            flags.append("DISAGREE")
        if woflan.get("error"):
            flags.append("WOFLAN-ERROR")
    return flags


def machine() -> dict[str, Any]:
    info: dict[str, Any] = {
        "python": platform.python_version(),
        "implementation": platform.python_implementation(),
        "platform": platform.platform(),
        "cpu_count": os.cpu_count(),
        "cpu": _cpu_model(),
    }
    try:
        info["pm4py"] = metadata.version("pm4py")
    except metadata.PackageNotFoundError:
        info["pm4py"] = None
    info.update(_git())
    return info


def _cpu_model() -> str | None:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or None


def _git() -> dict[str, Any]:
    """The commit measured, so a result file can be traced back to the code."""
    root = Path(__file__).resolve().parent.parent
    try:
        commit = subprocess.run(
            ["git", "rev-parse", "HEAD"], cwd=root, capture_output=True, text=True, timeout=10
        ).stdout.strip()
        dirty = subprocess.run(
            ["git", "status", "--porcelain", "--", "hrc", "bench"],
            cwd=root,
            capture_output=True,
            text=True,
            timeout=10,
        ).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return {}
    return {"commit": commit or None, "dirty": bool(dirty)}


def _duration(seconds: float | None) -> str:
    if seconds is None:
        return "-"
    if seconds < 1e-3:
        return f"{seconds * 1e6:.0f} µs"
    if seconds < 1:
        return f"{seconds * 1e3:.1f} ms"
    return f"{seconds:.2f} s"


def _verdict(sound: bool | None) -> str:
    return {True: "sound", False: "unsound", None: "-"}[sound]


def table(rows: Sequence[Mapping[str, Any]]) -> str:
    """Plain aligned text, one line per net."""
    header = [
        "net", "T", "exec P/T", "reduced P/T", "markings", "ours", "verdict", "witness", "peak mem",
        "floor", "ours/floor", "woflan", "woflan verdict", "ours/woflan", "flags",
    ]  # fmt: skip
    lines = [header]
    for row in rows:
        ours, woflan = row["ours"], row["woflan"]
        net = row["execution_net"]
        if ours["timed_out"] or ours.get("error"):
            our_time = "error" if ours.get("error") else f"> {ours['timeout']:g} s"
            verdict, witness, memory = "-", "-", "-"
            markings = reduced = "-"
        else:
            our_time = _duration(ours["seconds"])
            verdict = _verdict(ours["sound"])
            witness = {True: "yes", False: "NO", None: "-"}[ours["witness"]]
            if ours["witness"] and ours["witness_length"] is not None:
                witness += f" ({ours['witness_length']})"  # firings in the first witness
            peak = ours["peak_memory_bytes"]
            memory = "-" if peak is None else f"{peak / 2**20:.1f} MiB"
            markings = "-" if ours["markings"] is None else str(ours["markings"])
            stats = ours["stats"]
            reduced = (
                f"{stats['reduced_places']}/{stats['reduced_transitions']}"
                if "reduced_places" in stats and "reduced_transitions" in stats
                else "-"
            )
        if woflan is None:
            woflan_time, woflan_verdict = "not run", "-"
        elif woflan["timed_out"]:
            woflan_time = f"> {woflan['timeout']:g} s"
            woflan_verdict = "skipped" if woflan.get("skipped") else "-"
        elif woflan.get("error"):
            woflan_time, woflan_verdict = "error", "-"
        else:
            woflan_time, woflan_verdict = _duration(woflan["seconds"]), _verdict(woflan["sound"])
        ratio_floor = row.get("ratio_to_floor")
        ratio_woflan = row["ratio_to_woflan"]
        if ratio_woflan is None and woflan is not None and woflan["timed_out"] and ours["seconds"]:
            # Woflan did not finish: we are at least this much faster.
            ratio_text = f"< {ours['seconds'] / woflan['timeout']:.2g}"
        else:
            ratio_text = "-" if ratio_woflan is None else f"{ratio_woflan:.2g}"
        lines.append([
            f"{row['family']}-{row['transitions']}",
            str(row["transitions"]),
            f"{net['places']}/{net['transitions']}",
            reduced,
            markings,
            our_time,
            verdict,
            witness,
            memory,
            _duration(row["floor_seconds"]),
            "-" if ratio_floor is None else f"{ratio_floor:.0f}×",
            woflan_time,
            woflan_verdict,
            ratio_text,
            " ".join(row["flags"]),
        ])  # fmt: skip
    widths = [max(len(line[i]) for line in lines) for i in range(len(header))]
    left = {0, 6, 7, 12, 14}  # text columns read better left-aligned, numbers right-aligned
    out = []
    for line in lines:
        cells = [
            cell.ljust(width) if index in left else cell.rjust(width)
            for index, (cell, width) in enumerate(zip(line, widths, strict=True))
        ]
        out.append("  ".join(cells).rstrip())
    out.insert(1, "  ".join("-" * width for width in widths))
    return "\n".join(out)


def _summary(row: Mapping[str, Any]) -> str:
    """One line per net while the benchmark runs, so a slow Woflan shows where it is."""
    ours, woflan = row["ours"], row["woflan"]
    if ours.get("error"):
        text = f"ours failed: {ours['error']}"
    else:
        text = f"ours {'timed out' if ours['timed_out'] else _duration(ours['seconds'])}"
    if woflan is not None:
        if woflan["timed_out"]:
            text += f", woflan > {woflan['timeout']:g} s" + (
                " (skipped)" if woflan.get("skipped") else ""
            )
        else:
            text += f", woflan {_duration(woflan['seconds'])}"
    return text


def run(settings: Settings, progress: Callable[[str], None] = print) -> dict[str, Any]:
    """Measures every net and writes the result files; returns the result document."""
    started = datetime.now(UTC)
    load_before = load_average()
    rows = []
    woflan_overran: dict[str, str] = {}
    for size in sorted(settings.sizes):  # small first, so a Woflan timeout can skip larger ones
        for family in settings.families:
            progress(f"  {family}-{size} ...")
            row = measure(family, size, settings, woflan_overran.get(family))
            progress(f"    {_summary(row)}")
            woflan = row["woflan"]
            if woflan is not None and woflan["timed_out"] and family not in woflan_overran:
                woflan_overran[family] = f"timed out at {size} transitions"
            rows.append(row)
    result = {
        "benchmark": "soundness",
        "started": started.isoformat(timespec="seconds"),
        "seconds": (datetime.now(UTC) - started).total_seconds(),
        "machine": machine(),
        # Other work on the machine slows both checkers (Woflan most, as it runs
        # longest); the load average says how quiet the run was.
        "load_average": {"before": load_before, "after": load_average()},
        "settings": {
            "families": settings.families,
            "sizes": sorted(settings.sizes),
            "runs": settings.runs,
            "woflan": settings.woflan,
            "woflan_timeout": settings.woflan_timeout,
            "check_timeout": settings.check_timeout,
            "slow_seconds": SLOW_SECONDS,
        },
        "nets": rows,
    }
    settings.results_dir.mkdir(parents=True, exist_ok=True)
    stamp = started.strftime("%Y%m%dT%H%M%SZ")
    text = json.dumps(result, indent=2, ensure_ascii=False) + "\n"
    (settings.results_dir / f"soundness-{stamp}.json").write_text(text, encoding="utf-8")
    (settings.results_dir / "soundness-latest.json").write_text(text, encoding="utf-8")
    return result


def _csv(
    kind: Callable[[str], Any], allowed: Sequence[Any] | None = None
) -> Callable[[str], list[Any]]:
    def parse(text: str) -> list[Any]:
        values = [kind(part.strip()) for part in text.split(",") if part.strip()]
        if not values:
            raise argparse.ArgumentTypeError("give at least one value")
        if allowed is not None:
            unknown = [value for value in values if value not in allowed]
            if unknown:
                raise argparse.ArgumentTypeError(
                    f"unknown: {', '.join(map(str, unknown))}; one of {', '.join(map(str, allowed))}"
                )
        return values

    return parse


def parse_args(argv: Sequence[str] | None = None) -> Settings:
    parser = argparse.ArgumentParser(prog="python -m bench.run", description=__doc__.split("\n")[0])
    parser.add_argument("--quick", action="store_true", help="20 transitions only, no Woflan")
    parser.add_argument("--no-woflan", action="store_true", help="skip pm4py's Woflan")
    parser.add_argument("--sizes", type=_csv(int), default=list(SIZES), help="e.g. 20,100")
    parser.add_argument(
        "--families", type=_csv(str, FAMILIES), default=list(FAMILIES), help=", ".join(FAMILIES)
    )
    parser.add_argument("--runs", type=int, default=DEFAULT_RUNS, help="best of N (default 5)")
    parser.add_argument("--woflan-timeout", type=float, default=60.0, help="seconds (default 60)")
    parser.add_argument(
        "--check-timeout",
        type=float,
        default=120.0,
        help="guard on our own check, seconds (default 120; 0 = none)",
    )
    parser.add_argument("--results-dir", type=Path, default=RESULTS_DIR)
    args = parser.parse_args(argv)
    if any(size < 6 for size in args.sizes):
        parser.error("sizes must be at least 6 transitions")
    return Settings(
        families=args.families,
        sizes=[20] if args.quick else args.sizes,
        runs=max(1, args.runs),
        woflan=not (args.quick or args.no_woflan),
        woflan_timeout=args.woflan_timeout,
        check_timeout=args.check_timeout,
        results_dir=args.results_dir,
    )


def main(argv: Sequence[str] | None = None) -> int:
    settings = parse_args(argv)
    print(
        f"soundness benchmark: {', '.join(settings.families)} at {settings.sizes} transitions; "
        + ("Woflan limit " + f"{settings.woflan_timeout:g} s" if settings.woflan else "no Woflan"),
        flush=True,
    )
    result = run(settings, progress=lambda line: print(line, file=sys.stderr, flush=True))
    print(table(result["nets"]))
    load, cpus = result["load_average"]["before"], result["machine"]["cpu_count"]
    if load is not None and cpus and load[0] >= cpus:
        print(
            f"\nnote: load average {load[0]:g} on {cpus} CPUs when the run started: "
            "other work shared the machine, so the times are noisy"
        )
    flagged = [row for row in result["nets"] if row["flags"]]
    print(
        f"\n{len(result['nets'])} nets in {result['seconds']:.0f} s; "
        f"{len(flagged)} flagged; results in {settings.results_dir / 'soundness-latest.json'}"
    )
    # Slow nets and disagreements are findings for the reader; a crash of our check is a bug.
    return 1 if any("ENGINE-ERROR" in row["flags"] for row in result["nets"]) else 0


if __name__ == "__main__":
    sys.exit(main())
