"""The editor benchmark: its model and a quick run end to end in chromium."""

import json
from pathlib import Path

import pytest

from bench.editor import ELEMENTS, diagram_js_modules, dragged_task, element_count, main, model
from hrc.engine import check_document


def test_the_dragged_model_has_300_elements_and_is_a_sound_pattern() -> None:
    document = model(ELEMENTS)

    assert ELEMENTS <= element_count(document) < ELEMENTS + 10
    report = check_document(document)
    assert report.valid, [issue.message for issue in report.errors]
    task = dragged_task(document)
    assert any(
        t["id"] == task and t.get("performer")
        for p in document["processes"]
        for t in p["transitions"]
    )
    assert all("layout" in t for p in document["processes"] for t in p["transitions"])


def test_the_floor_is_diagram_js_with_the_modules_the_editor_imports() -> None:
    modules = diagram_js_modules()

    assert "diagram-js/lib/features/modeling" in modules
    assert "diagram-js/lib/features/palette" in modules
    assert all(module.startswith("diagram-js/lib/") for module in modules)


def test_a_quick_run_measures_the_bundle_and_the_frames(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    main(["--quick", "--results-dir", str(tmp_path)])

    report = json.loads((tmp_path / "editor-latest.json").read_text())
    bundle, frames = report["bundle"], report["frames"]
    # The pattern code comes on top of diagram-js: the editor cannot be smaller than its floor.
    assert bundle["ours"]["gzip"] > bundle["floor"]["gzip"] > 0
    assert bundle["ours"]["bytes"] > bundle["ours"]["gzip"]
    assert frames["canvas_elements"] >= ELEMENTS
    for row in ("idle_empty", "idle_model", "drag_model"):
        assert frames[row]["n"] == 60
        assert 0 <= frames[row]["p50_ms"] <= frames[row]["p95_ms"] <= frames[row]["max_ms"]
    # Handling a move and redrawing costs more than a frame where nothing happens.
    assert frames["drag_model"]["p50_ms"] > frames["idle_model"]["p50_ms"]
    assert "Frame time" in capsys.readouterr().out
