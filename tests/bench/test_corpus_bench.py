"""The corpus benchmark on a corpus of its own: our exports of two examples and a refused file."""

import json
from pathlib import Path

import pytest

from bench.corpus import best_ms, print_table, run
from hrc.engine import read_pattern
from hrc.engine.bpmn_export import pattern_to_bpmn
from hrc.engine.pnml import pattern_to_pnml
from tests.engine.builders import example


@pytest.fixture
def corpus(tmp_path: Path) -> Path:
    (tmp_path / "bpmn").mkdir()
    (tmp_path / "pnml").mkdir()
    assembly = read_pattern(example("synch_1o1c_assembly"))
    polishing = read_pattern(example("coop_1o1c_polishing"))
    (tmp_path / "bpmn" / "assembly.bpmn").write_text(pattern_to_bpmn(assembly))
    (tmp_path / "pnml" / "polishing.pnml").write_text(pattern_to_pnml(polishing))
    (tmp_path / "pnml" / "weighted.pnml").write_text(
        "<pnml><net id='n'><place id='p'/><transition id='t'/><arc id='a' source='p' "
        "target='t'><inscription><text>2</text></inscription></arc></net></pnml>"
    )
    return tmp_path


def test_best_ms_is_the_fastest_run() -> None:
    calls: list[int] = []
    assert best_ms(lambda: calls.append(1), 3) >= 0
    assert len(calls) == 3


def test_a_run_measures_every_file_against_its_parse_and_names_the_largest_model(
    corpus: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    report = run(corpus, runs=2, results_dir=tmp_path / "results")

    saved = json.loads((tmp_path / "results" / "corpus-latest.json").read_text())
    assert saved == json.loads(json.dumps(report))
    assert [row["file"] for row in saved["files"]] == [
        "bpmn/assembly.bpmn",
        "pnml/polishing.pnml",
        "pnml/weighted.pnml",
    ]
    assert [row["imported"] for row in saved["files"]] == [True, True, False]
    assert (saved["whole"]["files"], saved["whole"]["imported"]) == (3, 2)
    assert (saved["bpmn"]["files"], saved["pnml"]["files"]) == (1, 2)
    # Importing reads the XML and more: it cannot be cheaper than parsing it.
    assert saved["whole"]["ratio_to_floor"] > 1
    sizes = {row["file"]: row["nodes"] for row in saved["files"] if row["imported"]}
    assert saved["largest"]["file"] == max(sizes, key=lambda file: sizes[file])
    assert saved["largest"]["files"] == 1

    print_table(report)
    table = capsys.readouterr().out
    assert f"largest model: {saved['largest']['file']}" in table
    assert "whole corpus" in table


def test_a_folder_without_models_is_refused(tmp_path: Path) -> None:
    with pytest.raises(FileNotFoundError, match=r"no \.bpmn or \.pnml files"):
        run(tmp_path, runs=1, results_dir=tmp_path)
