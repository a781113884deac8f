"""Every model of the shared corpus, written by other tools, through its importer and the check.

`../shared/corpus/` (beside the checkout; `HRC_CORPUS` points elsewhere) holds real BPMN
models (the MIWG test suite with six tools' exports, Camunda's examples, process-mining
output), bpmn-js drawing fixtures and PNML from PIPE, pm4js and others. Each file either
imports and is checked, or is refused with messages that name its elements by name.

What happened to each file is kept in `corpus_expected.txt` beside this test, so a change
to the importers or the check shows as a diff of that table. `HRC_UPDATE_CORPUS=1`
rewrites the table from this run; commit it with the change that caused it.
"""

import difflib
import os
import re
import xml.etree.ElementTree as ET
from collections import Counter
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import pytest

from hrc.engine.bpmn import bpmn_to_pattern
from hrc.engine.budget import Budget
from hrc.engine.check import check_pattern
from hrc.engine.document import FormatError
from hrc.engine.issues import STRUCTURAL_CODES, Issue
from hrc.engine.pnml import pnml_to_pattern

ROOT = Path(__file__).resolve().parents[2]
CORPUS = Path(os.environ.get("HRC_CORPUS") or ROOT.parent / "shared" / "corpus")
TABLE = Path(__file__).with_name("corpus_expected.txt")
UPDATE = os.environ.get("HRC_UPDATE_CORPUS") == "1"
# Markings, not seconds: the verdict of a model too large to decide must not depend on the machine.
BUDGET = Budget(max_markings=50_000)
DRAWING_FIXTURES = "bpmnjs__"
"""bpmn-js' own test drawings: kept in the table, but not among the real models counted."""


@dataclass(frozen=True)
class Outcome:
    file: str
    """`bpmn/<name>.bpmn` or `pnml/<name>.pnml`."""
    imported: bool
    verdict: str
    """sound, unsound, too large, or undecided with the structural codes; refused: the ids named."""
    refusal: tuple[Issue, ...] = ()

    def row(self) -> str:
        return f"{self.file} | {'imported' if self.imported else 'refused'} | {self.verdict}"


def _files() -> list[Path]:
    return sorted([*CORPUS.glob("bpmn/*.bpmn"), *CORPUS.glob("pnml/*.pnml")])


def _outcome(path: Path) -> Outcome:
    name = f"{path.parent.name}/{path.name}"
    read = bpmn_to_pattern if path.suffix == ".bpmn" else pnml_to_pattern
    try:
        pattern = read(path.read_bytes())
    except FormatError as refusal:
        named = sorted({element for issue in refusal.issues for element in issue.elements})
        return Outcome(name, False, ", ".join(named) or "(no element)", tuple(refusal.issues))
    report = check_pattern(pattern, BUDGET)
    structural = sorted({e.code for e in report.errors if e.code in STRUCTURAL_CODES})
    if structural:
        verdict = f"undecided: {', '.join(structural)}"
    elif report.sound is None:
        verdict = "too large"
    else:
        verdict = "sound" if report.sound else "unsound"
    return Outcome(name, True, verdict)


@pytest.fixture(scope="module")
def outcomes() -> list[Outcome]:
    assert CORPUS.is_dir(), (
        f"The corpus is not at {CORPUS}: check out ../shared beside the repository, or set "
        "HRC_CORPUS to its corpus folder."
    )
    return [_outcome(path) for path in _files()]


def test_the_corpus_holds_the_bpmn_and_pnml_files_the_issue_counted(
    outcomes: list[Outcome],
) -> None:
    kinds = [outcome.file.split("/")[0] for outcome in outcomes]
    assert (kinds.count("bpmn"), kinds.count("pnml")) == (71, 22)
    assert len(_real_bpmn(outcomes)) == 50


def test_every_file_imports_and_checks_or_is_refused_as_the_table_says(
    outcomes: list[Outcome],
) -> None:
    table = "".join(f"{outcome.row()}\n" for outcome in outcomes)
    if UPDATE:
        TABLE.write_text(table)
    expected = TABLE.read_text() if TABLE.exists() else ""
    diff = "".join(
        difflib.unified_diff(
            expected.splitlines(keepends=True),
            table.splitlines(keepends=True),
            fromfile=f"{TABLE.name} (committed)",
            tofile="this run",
        )
    )
    assert not diff, (
        "The corpus results differ from the table; if the change is intended, run with "
        f"HRC_UPDATE_CORPUS=1 and commit {TABLE.name}:\n{diff}"
    )


def test_every_refusal_names_its_elements_and_each_by_its_name(outcomes: list[Outcome]) -> None:
    unnamed: list[str] = []
    for outcome in outcomes:
        names = _names(CORPUS / outcome.file)
        for issue in outcome.refusal:
            if not issue.elements:
                unnamed.append(f"{outcome.file}: names no element: {issue.message}")
            message = _spaced(issue.message)
            unnamed += [
                f"{outcome.file}: {element} is not called {names[element]!r}: {issue.message}"
                for element in issue.elements
                if names.get(element) and _spaced(names[element]) not in message
            ]
    assert not unnamed, "\n".join(unnamed)


def test_no_refusal_says_a_thing_twice(outcomes: list[Outcome]) -> None:
    """One issue per element: a node refused once is not named again by each flow touching it."""
    repeated: list[str] = []
    for outcome in outcomes:
        named = Counter(element for issue in outcome.refusal for element in set(issue.elements))
        said = Counter(issue.message for issue in outcome.refusal)
        repeated += [f"{outcome.file}: {e} in {n} issues" for e, n in named.items() if n > 1]
        repeated += [f"{outcome.file}: said {n} times: {m}" for m, n in said.items() if n > 1]
    assert not repeated, "\n".join(repeated)


def test_at_least_45_of_the_50_real_bpmn_models_import(outcomes: list[Outcome]) -> None:
    real = _real_bpmn(outcomes)
    refused = [outcome.file for outcome in real if not outcome.imported]
    assert len(real) - len(refused) >= 45, f"{len(refused)} refused: {refused}"


def test_every_bonita_export_imports(outcomes: list[Outcome]) -> None:
    bonita = [outcome for outcome in outcomes if "/miwg__Bonita-" in outcome.file]
    assert len(bonita) == 6
    assert [o.file for o in bonita if not o.imported] == []


def test_the_check_decides_the_soundness_of_every_real_bpmn_model_imported(
    outcomes: list[Outcome],
) -> None:
    undecided = [
        f"{outcome.file}: {outcome.verdict}"
        for outcome in _real_bpmn(outcomes)
        if outcome.imported and outcome.verdict not in ("sound", "unsound")
    ]
    assert not undecided, "\n".join(undecided)


def _real_bpmn(outcomes: list[Outcome]) -> list[Outcome]:
    return [
        outcome
        for outcome in outcomes
        if outcome.file.startswith("bpmn/") and not outcome.file[5:].startswith(DRAWING_FIXTURES)
    ]


def _names(path: Path) -> dict[str, str]:
    """Each element's name by id: BPMN's `name` attribute, PNML's `<name>` text or PIPE's value."""
    names: dict[str, str] = {}
    for element in ET.parse(path).getroot().iter():
        element_id = element.get("id")
        if not element_id:
            continue
        name = element.get("name") if path.suffix == ".bpmn" else _pnml_name(element)
        if name and name.strip():
            names[element_id] = name.strip()
    return names


def _pnml_name(element: ET.Element) -> str | None:
    for child in _local_children(element, "name"):
        for text in (*_local_children(child, "text"), *_local_children(child, "value")):
            return text.text
    return None


def _local_children(element: ET.Element, local: str) -> Iterator[ET.Element]:
    return (child for child in element if str(child.tag).rpartition("}")[2] == local)


def _spaced(text: str) -> str:
    """Whitespace made single spaces: a name written over lines is quoted on one."""
    return re.sub(r"\s+", " ", text).strip()
