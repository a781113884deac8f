"""The computations are pure: metrics, gantt and xes load no Django, so they run (and are
tested) on plain rows, and could run anywhere rows come from."""

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
PURE = ("hrc.analytics.metrics", "hrc.analytics.gantt", "hrc.analytics.xes")


def test_importing_the_computations_loads_no_django() -> None:
    script = (
        f"import sys, {', '.join(PURE)}; "
        "print(sorted(m for m in sys.modules if m.split('.')[0] in {'django', 'rest_framework'}))"
    )
    result = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, check=True, cwd=ROOT
    )
    assert result.stdout.strip() == "[]"
