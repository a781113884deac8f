"""`make bench` (fourth part): the pattern editor in the browser — bundle size and frame time.

In one run, on this machine:

(a) bundle: the gzip size (level 9) of what the editor page loads,
    frontend/dist/hrc/editor.js and editor.css, freshly built from the
    sources. Floor: the same diagram-js modules the editor uses, bundled alone
    by the same esbuild settings (diagram-js with no pattern code). Target:
    under 300 kB gzip.
(b) frame time while dragging a task in a model of about 300 elements (the
    `lanes` family of bench/nets.py laid out by the engine: places,
    transitions, arcs, constraints and lanes), in Debian's chromium driven by
    Playwright, on a static page (no server: the editor opens the laid-out
    draft with live checking off). In the page, at the start of each animation
    frame, a mousemove is dispatched to the drag diagram-js started on the
    task; a sample is the time from that dispatch until a message posted right
    after it runs, which is once the browser has done the frame's rendering
    work on the main thread: the event's handling plus style, layout and paint
    of the frame that shows it (the wait for the display's next refresh is not
    in it). Floors, the same loop with no event: the same page idle, and an
    empty model idle. Target: p95 under 16 ms (one frame at 60 Hz).

Results: bench/results/editor-<UTC>.json (and -latest.json), and a table.
"""

from __future__ import annotations

import argparse
import contextlib
import functools
import gzip
import http.server
import json
import os
import platform
import re
import shutil
import statistics
import subprocess
import tempfile
import threading
from collections.abc import Iterator, Sequence
from datetime import UTC, datetime
from importlib import metadata
from pathlib import Path
from typing import Any

from bench import nets
from bench.report import load_average, write_results
from hrc.engine.layout import lay_out

ROOT = Path(__file__).resolve().parent.parent
FRONTEND = ROOT / "frontend"
BUNDLE = FRONTEND / "dist" / "hrc"
RESULTS_DIR = Path(__file__).resolve().parent / "results"
CHROMIUM = "/usr/bin/chromium"
TARGET_GZIP_KB = 300.0
TARGET_FRAME_MS = 16.0
ELEMENTS = 300
# A frame is measured only after these, so the JIT and the drag's set-up are out of the figure.
WARMUP_FRAMES = 20

# One frame per sample; see the module docstring. Runs in the page.
MEASURE = """async ({ id, frames, warmup, drag }) => {
  const editor = window.hrcEditor;
  const registry = editor.get("elementRegistry");
  const nextFrame = () => new Promise((resolve) => requestAnimationFrame(resolve));
  const fire = (target, type, x, y) => target.dispatchEvent(new MouseEvent(type, {
    bubbles: true, cancelable: true, view: window, clientX: x, clientY: y,
    button: 0, buttons: type === "mouseup" ? 0 : 1,
  }));
  // From `work` at the start of a frame until the frame's rendering is done.
  const frame = (work) => new Promise((resolve) => requestAnimationFrame(() => {
    const start = performance.now();
    work();
    const channel = new MessageChannel();
    channel.port1.onmessage = () => resolve(performance.now() - start);
    channel.port2.postMessage(null);
  }));
  let x = 0, y = 0, before = null;
  if (drag) {
    const shape = registry.get(id);
    before = { x: shape.x, y: shape.y };
    editor.get("canvas").zoom(1, { x: shape.x + shape.width / 2, y: shape.y + shape.height / 2 });
    await nextFrame();
    const box = registry.getGraphics(id).getBoundingClientRect();
    x = box.x + box.width / 2;
    y = box.y + box.height / 2;
    fire(registry.getGraphics(id), "mousedown", x, y);
  }
  const samples = [];
  for (let i = 0; i < warmup + frames; i += 1) {
    // Back and forth within ±150 px, across lanes and back (the rules judge each position),
    // clear of the canvas edges where diagram-js would scroll the view.
    const move = () => fire(document, "mousemove", x + 150 * Math.sin(i / 15), y + 60 * Math.sin(i / 7));
    const took = await frame(drag ? move : () => {});
    if (i >= warmup) samples.push(took);
  }
  let moved = null;
  if (drag) {
    // Drop it along its lane: another lane would be refused (it is constrained with that actor).
    fire(document, "mousemove", x + 40, y);
    fire(document, "mouseup", x + 40, y);
    await nextFrame();
    const shape = registry.get(id);
    moved = shape.x !== before.x || shape.y !== before.y;
  }
  return { samples, moved, elements: registry.getAll().length - 2 };
}"""


def percentile(samples: Sequence[float], fraction: float) -> float:
    ordered = sorted(samples)
    return ordered[min(len(ordered) - 1, int(fraction * len(ordered)))]


def summary(samples: Sequence[float]) -> dict[str, float]:
    return {
        "n": len(samples),
        "p50_ms": round(percentile(samples, 0.50), 3),
        "p95_ms": round(percentile(samples, 0.95), 3),
        "mean_ms": round(statistics.fmean(samples), 3),
        "max_ms": round(max(samples), 3),
    }


# (a) the bundle ------------------------------------------------------------------------------


def build_editor() -> None:
    """Builds the frontend from its sources, so the figures are the code's, not an old build's."""
    if not (FRONTEND / "node_modules").is_dir():
        raise SystemExit("frontend/node_modules is missing: run `make install` first.")
    subprocess.run(
        ["npm", "run", "--silent", "build"], cwd=FRONTEND, check=True, capture_output=True
    )


def gzip_size(data: bytes) -> int:
    return len(gzip.compress(data, compresslevel=9, mtime=0))


def sizes(files: dict[str, bytes]) -> dict[str, Any]:
    rows = {name: {"bytes": len(data), "gzip": gzip_size(data)} for name, data in files.items()}
    return {
        "files": rows,
        "bytes": sum(row["bytes"] for row in rows.values()),
        "gzip": sum(row["gzip"] for row in rows.values()),
    }


def diagram_js_modules() -> list[str]:
    """Every diagram-js module (features, navigation) the editor's sources import."""
    found: set[str] = set()
    pattern = re.compile(r'from "(diagram-js/lib/(?:features|navigation)/[\w-]+)"')
    for source in (FRONTEND / "src" / "editor").rglob("*.ts"):
        found.update(pattern.findall(source.read_text()))
    return sorted(found)


def floor_bundle(modules: list[str]) -> dict[str, bytes]:
    """diagram-js with the editor's diagram-js modules and its CSS, bundled as the editor is."""
    imports = "\n".join(f'import m{i} from "{module}";' for i, module in enumerate(modules))
    entry = (
        'import Diagram from "diagram-js";\nimport "diagram-js/assets/diagram-js.css";\n'
        f"{imports}\n"
        f"export const diagram = (container) => new Diagram({{ canvas: {{ container }}, "
        f"modules: [{', '.join(f'm{i}' for i in range(len(modules)))}] }});\n"
    )
    with tempfile.TemporaryDirectory() as out:
        script = (
            'import { build } from "esbuild";\n'
            f"await build({{ stdin: {{ contents: {json.dumps(entry)}, resolveDir: process.cwd(), "
            f'loader: "js" }}, bundle: true, minify: true, format: "esm", target: "es2020", '
            f'outfile: {json.dumps(str(Path(out) / "floor.js"))}, logLevel: "error" }});\n'
        )
        subprocess.run(
            ["node", "--input-type=module", "-e", script],
            cwd=FRONTEND,
            check=True,
            capture_output=True,
        )
        return {path.name: path.read_bytes() for path in sorted(Path(out).iterdir())}


# (b) frame time ------------------------------------------------------------------------------


def model(elements: int) -> dict[str, Any]:
    """The smallest laid-out `lanes` pattern with at least `elements` diagram elements."""
    transitions = 10
    while True:
        document = lay_out(nets.lanes(transitions))
        if element_count(document) >= elements:
            return document
        transitions += 1


def element_count(document: dict[str, Any]) -> int:
    """What the canvas holds: lanes, places, transitions, arcs and constraints."""
    nodes = sum(
        len(p["places"]) + len(p["transitions"]) + len(p["arcs"]) for p in document["processes"]
    )
    return len(document["actors"]) + nodes + len(document["constraints"])


def dragged_task(document: dict[str, Any]) -> str:
    """A constrained task in the middle of the model: it drags arcs and a constraint along."""
    constrained = [str(c["to"]) for c in document["constraints"]]
    return constrained[len(constrained) // 2]


def _page(site: Path, name: str, document: dict[str, Any]) -> str:
    config = {
        "pattern": {"id": None, "name": document.get("name", "bench"), "canWrite": True},
        "draft": document,
        "liveChecking": False,
    }
    script = json.dumps(config).replace("</", "<\\/")
    (site / f"{name}.html").write_text(
        '<!doctype html><html><head><meta charset="utf-8">'
        '<link rel="stylesheet" href="hrc/editor.css"></head><body style="margin:0">'
        '<div id="hrc-editor"></div>'
        f'<script id="hrc-editor-config" type="application/json">{script}</script>'
        '<script type="module" src="hrc/editor.js"></script></body></html>'
    )
    return f"{name}.html"


class _QuietHandler(http.server.SimpleHTTPRequestHandler):
    def log_message(self, format: str, *args: Any) -> None:
        pass


@contextlib.contextmanager
def static_site(site: Path) -> Iterator[str]:
    """Serves `site` on a free loopback port for the run."""
    handler = functools.partial(_QuietHandler, directory=str(site))
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        yield f"http://127.0.0.1:{server.server_address[1]}"
    finally:
        server.shutdown()
        server.server_close()


def measure_frames(document: dict[str, Any], frames: int) -> dict[str, Any]:
    from playwright.sync_api import sync_playwright

    task = dragged_task(document)
    empty: dict[str, Any] = {
        "format": "hrc-pattern/1",
        "name": "empty",
        "actors": [],
        "processes": [{"id": "N", "actors": [], "places": [], "transitions": [], "arcs": []}],
        "constraints": [],
        "layout": {"lanes": [], "width": 1000, "height": 400},
    }
    with tempfile.TemporaryDirectory() as scratch:
        site = Path(scratch)
        shutil.copytree(BUNDLE, site / "hrc")
        pages = {"model": _page(site, "model", document), "empty": _page(site, "empty", empty)}
        with static_site(site) as url, sync_playwright() as driver:
            browser = driver.chromium.launch(executable_path=CHROMIUM, args=["--no-sandbox"])
            try:
                results = {}
                for row, page_name, drag in (
                    ("idle_empty", "empty", False),
                    ("idle_model", "model", False),
                    ("drag_model", "model", True),
                ):
                    page = browser.new_page(viewport={"width": 1280, "height": 800})
                    page.goto(f"{url}/{pages[page_name]}")
                    page.wait_for_selector("#hrc-editor[data-ready=true]", state="attached")
                    results[row] = page.evaluate(
                        MEASURE,
                        {"id": task, "frames": frames, "warmup": WARMUP_FRAMES, "drag": drag},
                    )
                    page.close()
                version = browser.version
            finally:
                browser.close()
    if not results["drag_model"]["moved"]:
        raise RuntimeError(f"the drag of {task} did not move it: the measurement is void")
    return {"task": task, "chromium": version, **results}


# The run -------------------------------------------------------------------------------------


def run(frames: int, results_dir: Path) -> dict[str, Any]:
    build_editor()
    ours = sizes({name: (BUNDLE / name).read_bytes() for name in ("editor.js", "editor.css")})
    modules = diagram_js_modules()
    floor = sizes(floor_bundle(modules))
    document = model(ELEMENTS)
    measured = measure_frames(document, frames)
    rows = {
        name: summary(measured[name]["samples"])
        for name in ("idle_empty", "idle_model", "drag_model")
    }
    drag = rows["drag_model"]
    report = {
        "benchmark": "editor",
        "when": datetime.now(UTC).isoformat(timespec="seconds"),
        "machine": machine(),
        "bundle": {
            "ours": ours,
            "floor": {**floor, "modules": modules},
            "ratio_gzip": round(ours["gzip"] / floor["gzip"], 3),
            "target_gzip_kb": TARGET_GZIP_KB,
            "meets_target": ours["gzip"] / 1000 < TARGET_GZIP_KB,
        },
        "frames": {
            "model_elements": element_count(document),
            "canvas_elements": measured["drag_model"]["elements"],
            "dragged": measured["task"],
            "chromium": measured["chromium"],
            "warmup": WARMUP_FRAMES,
            **rows,
            "ratio_p50": round(drag["p50_ms"] / rows["idle_model"]["p50_ms"], 3),
            "ratio_p95": round(drag["p95_ms"] / rows["idle_model"]["p95_ms"], 3),
            "target_p95_ms": TARGET_FRAME_MS,
            "meets_target": drag["p95_ms"] < TARGET_FRAME_MS,
        },
    }
    write_results(results_dir, "editor", report)
    return report


def machine() -> dict[str, Any]:
    load = load_average()
    commit = subprocess.run(
        ["git", "rev-parse", "HEAD"], cwd=ROOT, capture_output=True, text=True, check=False
    ).stdout.strip()
    return {
        "platform": platform.platform(),
        "python": platform.python_version(),
        "cpus": os.cpu_count(),
        "load": load,
        "playwright": metadata.version("playwright"),
        "commit": commit or None,
    }


def print_table(report: dict[str, Any]) -> None:
    bundle, frames = report["bundle"], report["frames"]
    print("\nEditor bundle (gzip -9), built from the sources")
    print(f"{'':44} {'bytes':>10} {'gzip kB':>9}")
    for name, row in bundle["ours"]["files"].items():
        print(f"{'ours: ' + name:44} {row['bytes']:10} {row['gzip'] / 1000:9.1f}")
    print(f"{'ours: total':44} {bundle['ours']['bytes']:10} {bundle['ours']['gzip'] / 1000:9.1f}")
    floor = f"floor: diagram-js, its {len(bundle['floor']['modules'])} modules we use"
    print(f"{floor:44} {bundle['floor']['bytes']:10} {bundle['floor']['gzip'] / 1000:9.1f}")
    verdict = "meets" if bundle["meets_target"] else "MISSES"
    print(
        f"ratio ours / floor {bundle['ratio_gzip']:.2f}; target < {TARGET_GZIP_KB:.0f} kB gzip: {verdict}"
    )
    print(
        f"\nFrame time, {frames['canvas_elements']} elements on the canvas, dragging "
        f"{frames['dragged']} ({frames['drag_model']['n']} frames, {frames['chromium']})"
    )
    print(f"{'':44} {'p50 ms':>8} {'p95 ms':>8} {'max ms':>8}")
    labels = {
        "idle_empty": "floor: empty model, idle",
        "idle_model": "floor: same model, idle",
        "drag_model": "ours: dragging a task",
    }
    for key, label in labels.items():
        row = frames[key]
        print(f"{label:44} {row['p50_ms']:8.2f} {row['p95_ms']:8.2f} {row['max_ms']:8.2f}")
    print(
        f"{'ratio dragging / idle model':44} {frames['ratio_p50']:8.2f} {frames['ratio_p95']:8.2f}"
    )
    verdict = "meets" if frames["meets_target"] else "MISSES"
    load = report["machine"]["load"]
    print(
        f"target p95 < {TARGET_FRAME_MS:.0f} ms: {verdict}"
        + (f" (load average {load[0]:.2f})" if load else "")
    )


def main(argv: Sequence[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    parser.add_argument("--frames", type=int, default=300, help="measured frames per row")
    parser.add_argument("--quick", action="store_true", help="60 frames (the test's run)")
    parser.add_argument("--results-dir", type=Path, default=RESULTS_DIR)
    arguments = parser.parse_args(argv)
    frames = 60 if arguments.quick else arguments.frames
    if frames < 1:
        parser.error("--frames must be at least 1")
    print_table(run(frames, arguments.results_dir))


if __name__ == "__main__":
    main()
