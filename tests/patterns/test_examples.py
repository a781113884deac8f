"""The example library: the thesis' eight instantiations of section 4.3, each valid and sound."""

import json
import re
from pathlib import Path
from typing import Any

import pytest

from hrc.engine import check_document
from hrc.patterns.checking import interactive_budget

EXAMPLES_DIR = Path(__file__).resolve().parents[2] / "hrc" / "patterns" / "examples"
EXAMPLES = sorted(EXAMPLES_DIR.glob("*.json"))

PATTERN_OF_PREFIX = {
    "synch": "synchronized",
    "coop": "cooperation",
    "coll": "collaboration",
    "coex": "coexistence",
}

# "synch_1o2c_spot_taping": pattern prefix, operators, cobots, use case.
NAME = re.compile(r"^(?P<prefix>[a-z]+)_(?P<operators>\d)o(?P<cobots>\d)c_[a-z_]+$")


def load(path: Path) -> dict[str, Any]:
    document: dict[str, Any] = json.loads(path.read_text(encoding="utf-8"))
    return document


def test_the_library_holds_exactly_the_eight_thesis_instantiations() -> None:
    assert [path.stem for path in EXAMPLES] == [
        "coex_1o1c_pick_and_place",
        "coex_2o1c_packaging_palletizing",
        "coll_1o1c_collaborative_assembly",
        "coll_1o2c_assisted_handling",
        "coop_1o1c_polishing",
        "coop_2o2c_quality_inspection",
        "synch_1o1c_assembly",
        "synch_1o2c_spot_taping",
    ]


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda path: path.stem)
def test_example_is_valid_and_sound(path: Path) -> None:
    report = check_document(load(path))

    assert report.errors == ()
    assert report.valid is True
    assert report.sound is True


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda path: path.stem)
def test_example_is_classified_as_the_pattern_its_name_declares(path: Path) -> None:
    document = load(path)
    match = NAME.match(path.stem)
    assert match is not None, f"{path.name} does not follow pattern_xOyC_use_case"

    declared = document["declared_pattern"]
    assert PATTERN_OF_PREFIX[match["prefix"]] == declared
    assert declared in check_document(document).patterns


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda path: path.stem)
def test_example_has_the_operators_and_cobots_its_name_counts(path: Path) -> None:
    match = NAME.match(path.stem)
    assert match is not None
    types = [actor["type"] for actor in load(path)["actors"]]

    assert types.count("operator") == int(match["operators"])
    assert types.count("cobot") == int(match["cobots"])


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda path: path.stem)
def test_example_cites_its_thesis_section_and_name(path: Path) -> None:
    match = NAME.match(path.stem)
    assert match is not None
    thesis_name = f"CP_{match['prefix']}_{match['operators']}O{match['cobots']}C"

    source = load(path)["source"]
    assert re.match(rf"thesis, section 4\.3\.[1-4], {thesis_name}\b", source), source


@pytest.mark.parametrize(
    "path", EXAMPLES + sorted((EXAMPLES_DIR / "use_cases").glob("*.json")), ids=lambda p: p.stem
)
def test_a_check_within_a_requests_budget_decides_each_example_as_an_unbounded_one_does(
    path: Path,
) -> None:
    document = load(path)

    bounded = check_document(document, interactive_budget())

    assert bounded.sound is True
    assert bounded.as_dict() == check_document(document).as_dict()
