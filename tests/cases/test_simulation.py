"""What `run_pattern --simulate` makes up: operators' form data, and how a document's cases differ."""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any

import pytest
from django.core.management import CommandError, call_command

from hrc.cases.simulation import CaseVariant, case_variants, example_for
from hrc.engine import read_pattern
from tests.engine.builders import example

FORM: dict[str, Any] = {
    "type": "object",
    "required": ["position", "last", "count", "verdict", "note", "size"],
    "properties": {
        "position": {
            "enum": ["top left", "top right", "bottom"],
            "examples": ["bottom", "top left"],
        },
        "last": {"type": "boolean", "default": False},
        "count": {"type": "integer", "minimum": 3},
        "verdict": {"enum": ["OK", "NOK"]},
        "note": {"type": "string"},
        "size": {"type": "object", "required": ["w"], "properties": {"w": {"examples": [1, 2, 3]}}},
        "optional": {"type": "string", "examples": ["never entered"]},
    },
}


def test_an_operator_answers_a_fields_examples_in_turn_then_its_default_choice_or_type() -> None:
    answers = [example_for(FORM, n) for n in range(3)]

    assert [a["position"] for a in answers] == ["bottom", "top left", "bottom"]
    assert [a["size"] for a in answers] == [{"w": 1}, {"w": 2}, {"w": 3}]
    assert answers[0] == {
        "position": "bottom",
        "last": False,
        "count": 3,
        "verdict": "OK",
        "note": "ok",
        "size": {"w": 1},
    }
    assert example_for(None) == {} == example_for({"type": "object"})


def _document(simulation: object) -> dict[str, Any]:
    """The thesis' spot taping (actors o, c1, c2) with `simulation`."""
    document = example("synch_1o2c_spot_taping")
    document["simulation"] = simulation
    return document


def test_case_variants_say_who_stands_in_for_whom_and_with_what_data() -> None:
    document = _document(
        {
            "cases": [
                {"name": "first"},
                {"data": {"workspace": 1}, "actors": {"o": "o2", "c1": "c2", "c2": "c1"}},
            ]
        }
    )

    variants = case_variants(document, read_pattern(document))

    assert variants == [
        CaseVariant("first", {}, {}),
        CaseVariant("simulation case 2", {"workspace": 1}, {"o": "o2", "c1": "c2", "c2": "c1"}),
    ]
    assert case_variants({}, read_pattern(document)) == []


@pytest.mark.parametrize(
    ("simulation", "complaint"),
    [
        ([], '"simulation" must be an object'),
        ({"cases": {"o": "o2"}}, '"cases" is a list'),
        ({"cases": ["operator 2"]}, "simulation case 1 must be an object"),
        ({"cases": [{"data": [1]}]}, "its data must be an object"),
        ({"cases": [{"actors": ["o"]}]}, "its actors must map"),
        ({"cases": [{"actors": {"x": "o2"}}]}, "no actor 'x'"),
        ({"cases": [{"actors": {"o": "operator 2"}}]}, "letters, digits"),
        ({"cases": [{"actors": {"o": "c1"}}]}, "o and c1 are not both operators"),
    ],
)
def test_malformed_case_variants_are_refused_saying_what_is_wrong(
    simulation: object, complaint: str
) -> None:
    document = _document(simulation)

    with pytest.raises(ValueError, match=re.escape(complaint)):
        case_variants(document, read_pattern(document))


def test_run_pattern_refuses_a_document_with_malformed_case_variants(tmp_path: Path) -> None:
    path = tmp_path / "variants.json"
    path.write_text(json.dumps(_document({"cases": [{"actors": {"nobody": "x"}}]})))

    with pytest.raises(CommandError, match="cannot run: simulation case 1: the pattern has no"):
        call_command("run_pattern", str(path), "--simulate")
