"""The sound models of other tools run: every real BPMN model of the shared corpus that imports
and checks sound runs to completion under `run_pattern --simulate`, once its lanes are given
actor types (here: every lane an operator, as no lane of the corpus holds a cobot program),
timers and messages between pools included.

Which models are sound is the corpus table's (tests/engine/corpus_expected.txt), so a model the
importer newly makes sound is run here too.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from hrc.engine.bpmn import bpmn_to_document
from tests.cases.test_run_pattern import run_pattern
from tests.engine.test_corpus import CORPUS, TABLE

REAL = ("camex__", "miwg__", "pm4js__")


def _sound_real_models() -> list[str]:
    rows = [line.split(" | ") for line in TABLE.read_text().splitlines() if line.strip()]
    return [
        name.removeprefix("bpmn/")
        for name, outcome, *verdict in rows
        if name.startswith("bpmn/")
        and name.removeprefix("bpmn/").startswith(REAL)
        and outcome == "imported"
        and verdict == ["sound"]
    ]


SOUND = _sound_real_models()


def test_most_real_models_are_sound_and_run_here() -> None:
    assert len(SOUND) >= 40


@pytest.mark.django_db(transaction=True)
@pytest.mark.parametrize("name", SOUND, ids=[name.removesuffix(".bpmn") for name in SOUND])
def test_a_sound_imported_model_runs_to_completion(name: str, tmp_path: Path) -> None:
    document = bpmn_to_document((CORPUS / "bpmn" / name).read_bytes())
    for actor in document["actors"]:
        actor["type"] = "operator"
    path = tmp_path / "model.json"
    path.write_text(json.dumps(document))

    events = run_pattern(
        path, "--time-scale", "0", "--timer-scale", "0.0001", "--seed", "3", "--timeout", "60"
    )

    assert events[-1]["event"] == "case-completed", events[-8:]
    started = [e["task"] for e in events if e["event"] == "task-started"]
    assert started, "no task ran"
