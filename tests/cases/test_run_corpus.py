"""The sound models of other tools run: every real BPMN model of the shared corpus that imports
and checks sound runs to completion under `run_pattern --simulate`, once its lanes are given
actor types (here: every lane an operator, as no lane of the corpus holds a cobot program),
timers and messages between pools included.

Which models are sound is the corpus table's (tests/engine/corpus_expected.txt), so a model the
importer newly makes sound is run here too. A sound model whose import left pieces to rewrite (a
condition in FEEL, a timer with no time, a call activity naming nothing, a loop or multi-instance
count known only at run time: `"rewrite"` keys) is a draft until its engineer rewrites them, as
the issue asks; run_pattern refuses it, and the test asserts that it does, naming each piece.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from django.core.management.base import CommandError

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


def _to_rewrite(name: str) -> list[str]:
    """What the import of a model left to rewrite: each `"rewrite"` key's text."""
    document = bpmn_to_document((CORPUS / "bpmn" / name).read_bytes())
    return [
        element["rewrite"]
        for process in document["processes"]
        for element in [*process["places"], *process["transitions"]]
        if "rewrite" in element
    ]


SOUND = _sound_real_models()
TO_REWRITE = {name: rewrites for name in SOUND if (rewrites := _to_rewrite(name))}
RUNNABLE = [name for name in SOUND if name not in TO_REWRITE]


def test_most_real_models_are_sound_and_most_of_those_run_here() -> None:
    assert len(SOUND) >= 40
    assert len(RUNNABLE) >= 35


def _model(name: str, tmp_path: Path) -> Path:
    document = bpmn_to_document((CORPUS / "bpmn" / name).read_bytes())
    for actor in document["actors"]:
        actor["type"] = "operator"
    path = tmp_path / "model.json"
    path.write_text(json.dumps(document))
    return path


@pytest.mark.django_db(transaction=True)
@pytest.mark.parametrize("name", RUNNABLE, ids=[name.removesuffix(".bpmn") for name in RUNNABLE])
def test_a_sound_imported_model_runs_to_completion(name: str, tmp_path: Path) -> None:
    path = _model(name, tmp_path)

    events = run_pattern(
        path, "--time-scale", "0", "--timer-scale", "0.0001", "--seed", "3", "--timeout", "60"
    )

    assert events[-1]["event"] == "case-completed", events[-8:]
    started = [e["task"] for e in events if e["event"] == "task-started"]
    assert started, "no task ran"


@pytest.mark.django_db(transaction=True)
@pytest.mark.parametrize(
    "name", TO_REWRITE, ids=[name.removesuffix(".bpmn") for name in TO_REWRITE]
)
def test_a_sound_model_with_pieces_to_rewrite_is_refused_naming_each(
    name: str, tmp_path: Path
) -> None:
    with pytest.raises(CommandError, match="cannot run: to-rewrite") as refusal:
        run_pattern(_model(name, tmp_path), "--time-scale", "0", "--timeout", "5")

    assert all(
        " ".join(text.split()) in " ".join(str(refusal.value).split()) for text in TO_REWRITE[name]
    )
