"""Runs captured events through the tablet's own store (frontend/src/live/store.ts) with node."""

from __future__ import annotations

import functools
import json
import subprocess
import tempfile
from pathlib import Path
from typing import Any

from django.conf import settings

FRONTEND = Path(settings.BASE_DIR) / "frontend"


@functools.cache
def _bundle() -> Path:
    out = Path(tempfile.mkdtemp(prefix="hrc-replay-")) / "replay.mjs"
    subprocess.run(
        [str(FRONTEND / "node_modules" / ".bin" / "esbuild"), "test/live/replay.mjs", "--bundle",
         "--platform=node", "--format=esm", f"--outfile={out}", "--log-level=warning"],
        cwd=FRONTEND, check=True,
    )  # fmt: skip
    return out


def replay(events: list[dict[str, Any]]) -> dict[str, Any]:
    """{"state": the store's state in the snapshot's shape, "holes": bool, "outcomes": [...]}."""
    done = subprocess.run(
        ["node", str(_bundle())],
        input=json.dumps({"events": events}),
        capture_output=True, text=True, check=True, timeout=60,
    )  # fmt: skip
    result: dict[str, Any] = json.loads(done.stdout)
    return result
