"""`make bench` (second part): the cobot step handshake against its floor.

One simulated gateway runs as its own process with --time-scale 0, so a
step takes no simulated time and what is left is signalling. In one run:
- the floor: a raw asyncua write of one Int32 register and its response,
  the cheapest round trip any client of this gateway can make;
- ours: one zero-time step through the driver: step, poses, token and bit
  in one write, the acknowledgement seen through the subscription, the bit
  cleared, its fall seen — the full four-phase handshake.
Each is timed over --steps iterations after a warm-up; p50, p99 and the
ratio of ours to the floor go to bench/results/handshake-<UTC>.json (and
-latest.json) and to a table. Target (issue 3): p50 <= 5 ms, p99 <= 20 ms.
"""

from __future__ import annotations

import argparse
import asyncio
import os
import platform
import statistics
import tempfile
import time
from datetime import UTC, datetime
from importlib import metadata
from pathlib import Path
from typing import Any

from bench.report import write_results

RESULTS_DIR = Path(__file__).resolve().parent / "results"
TARGET_P50_MS = 5.0
TARGET_P99_MS = 20.0
PROGRAM = "Coexistence_PickAndPlace"
STEP = 3  # "pick": a 2 s wait, zero at time scale 0


def percentile(samples: list[float], fraction: float) -> float:
    ordered = sorted(samples)
    return ordered[min(len(ordered) - 1, int(fraction * len(ordered)))]


async def _measure(endpoint: str, steps: int, warmup: int) -> dict[str, list[float]]:
    from asyncua import Client, ua

    from hrc.cobots.drivers.base import Fence, StepCommand
    from hrc.cobots.drivers.opcua.driver import OpcUaDriver
    from hrc_gateway import urua

    driver = OpcUaDriver("cobot1", endpoint, step_timeout=10.0)
    await driver.call("PowerOn", timeout=30)
    await driver.call("SelectProgram", PROGRAM)
    await driver.call("StartProgram")

    raw = Client(endpoint)
    await raw.connect()
    register = raw.get_node(urua.node_id("cobot1", urua.register_path("Inputs", "Int30")))
    floor: list[float] = []
    ours: list[float] = []
    try:
        for index in range(warmup + steps):
            started = time.perf_counter()
            await register.write_value(ua.Variant(index, ua.VariantType.Int32))
            elapsed = time.perf_counter() - started
            if index >= warmup:
                floor.append(elapsed * 1000)
        for index in range(warmup + steps):
            command = StepCommand(step=STEP, workspace=0, fence=Fence(index + 1, 1))
            started = time.perf_counter()
            result = await driver.run_step(command)
            elapsed = time.perf_counter() - started
            if result.outcome != "ran":
                raise RuntimeError(f"step {index} came back {result.outcome!r}")
            if index >= warmup:
                ours.append(elapsed * 1000)
    finally:
        await raw.disconnect()
        await driver.close()
    return {"floor": floor, "ours": ours}


def run(steps: int, warmup: int, results_dir: Path) -> dict[str, Any]:
    os.environ.setdefault("DJANGO_SETTINGS_MODULE", "hrc.settings.dev")
    from hrc.cobots.simulated import GatewayProcess

    with tempfile.TemporaryDirectory() as scratch:
        gateway = GatewayProcess("cobot1", Path(scratch) / "cobot1.json", time_scale=0.0)
        gateway.start()
        try:
            samples = asyncio.run(_measure(gateway.endpoint, steps, warmup))
        finally:
            gateway.stop()
    rows = {name: _summary(values) for name, values in samples.items()}
    report = {
        "benchmark": "handshake",
        "when": datetime.now(UTC).isoformat(timespec="seconds"),
        "machine": {
            "platform": platform.platform(),
            "python": platform.python_version(),
            "cpus": os.cpu_count(),
            "load": os.getloadavg(),
            "asyncua": metadata.version("asyncua"),
        },
        "steps": steps,
        "warmup": warmup,
        "floor": rows["floor"],
        "ours": rows["ours"],
        "ratio_p50": rows["ours"]["p50_ms"] / rows["floor"]["p50_ms"],
        "ratio_p99": rows["ours"]["p99_ms"] / rows["floor"]["p99_ms"],
        "target": {"p50_ms": TARGET_P50_MS, "p99_ms": TARGET_P99_MS},
        "meets_target": rows["ours"]["p50_ms"] <= TARGET_P50_MS
        and rows["ours"]["p99_ms"] <= TARGET_P99_MS,
    }
    write_results(results_dir, "handshake", report)
    return report


def _summary(values: list[float]) -> dict[str, float]:
    return {
        "n": len(values),
        "p50_ms": round(percentile(values, 0.50), 3),
        "p99_ms": round(percentile(values, 0.99), 3),
        "mean_ms": round(statistics.fmean(values), 3),
        "max_ms": round(max(values), 3),
    }


def print_table(report: dict[str, Any]) -> None:
    print(f"\nCobot step handshake, {report['steps']} steps, loopback, zero-time simulated step")
    print(f"{'':34} {'p50 ms':>8} {'p99 ms':>8} {'max ms':>8}")
    labels = {
        "floor": "floor: raw asyncua write round trip",
        "ours": "ours: driver step, 4-phase",
    }
    for key, label in labels.items():
        row = report[key]
        print(f"{label:34} {row['p50_ms']:8.3f} {row['p99_ms']:8.3f} {row['max_ms']:8.3f}")
    print(f"{'ratio ours / floor':34} {report['ratio_p50']:8.2f} {report['ratio_p99']:8.2f}")
    verdict = "meets" if report["meets_target"] else "MISSES"
    print(
        f"target p50 <= {TARGET_P50_MS} ms, p99 <= {TARGET_P99_MS} ms: {verdict} "
        f"(load average {report['machine']['load'][0]:.2f})"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=1000, help="timed iterations (default 1000)")
    parser.add_argument("--warmup", type=int, default=100, help="untimed iterations first")
    parser.add_argument("--results-dir", type=Path, default=RESULTS_DIR)
    arguments = parser.parse_args()
    if arguments.steps < 1:
        parser.error("--steps must be at least 1")
    print_table(run(arguments.steps, arguments.warmup, arguments.results_dir))


if __name__ == "__main__":
    main()
