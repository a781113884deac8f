"""The handshake benchmark runs end to end against a real gateway and writes its report."""

import json
from pathlib import Path

import pytest

from bench.handshake import percentile, run


def test_percentiles_pick_from_the_sorted_samples() -> None:
    samples = [float(n) for n in range(100, 0, -1)]
    assert percentile(samples, 0.5) == 51.0
    assert percentile(samples, 0.99) == 100.0
    assert percentile([3.0], 0.99) == 3.0


def test_a_short_run_writes_the_report(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    report = run(steps=30, warmup=5, results_dir=tmp_path)
    saved = json.loads((tmp_path / "handshake-latest.json").read_text())
    assert saved == json.loads(json.dumps(report))
    for row in ("floor", "ours"):
        assert saved[row]["n"] == 30
        assert 0 < saved[row]["p50_ms"] <= saved[row]["p99_ms"] <= saved[row]["max_ms"]
    # A four-phase step cannot be cheaper than one write round trip.
    assert saved["ratio_p50"] > 1
