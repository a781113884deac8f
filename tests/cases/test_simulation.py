"""How a document's cases differ under `run_pattern --simulate` (its operators' form data is the
engine's rule: tests/engine/test_forms.py)."""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any

import pytest
from django.core.management import CommandError, call_command

from hrc.cases.simulation import case_variants
from hrc.engine import read_pattern
from hrc.engine.prediction import CaseVariant
from hrc.engine.runtime import CaseNet
from tests.engine.builders import example


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

    variants = case_variants(document, CaseNet(read_pattern(document)))

    assert variants == (
        CaseVariant("first", {}, {}),
        CaseVariant("simulation case 2", {"workspace": 1}, {"o": "o2", "c1": "c2", "c2": "c1"}),
    )
    assert case_variants({}, CaseNet(read_pattern(document))) == ()


@pytest.mark.parametrize(
    ("simulation", "complaint"),
    [
        ([], '"simulation" must be an object'),
        ({"cases": {"o": "o2"}}, '"cases" is a list'),
        ({"cases": ["operator 2"]}, "simulation case 1 must be an object"),
        ({"cases": [{"data": [1]}]}, "data and actors must be objects"),
        ({"cases": [{"actors": ["o"]}]}, "data and actors must be objects"),
        ({"cases": [{"actors": {"o": ["o2"]}}]}, "letters, digits"),
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
        case_variants(document, CaseNet(read_pattern(document)))


def test_run_pattern_refuses_a_document_with_malformed_case_variants(tmp_path: Path) -> None:
    path = tmp_path / "variants.json"
    path.write_text(json.dumps(_document({"cases": [{"actors": {"nobody": "x"}}]})))

    with pytest.raises(CommandError, match="cannot run: simulation case 1: the pattern has no"):
        call_command("run_pattern", str(path), "--simulate")
