"""`manage.py predict FILE`: a table or the API's JSON; a bad file or option ends with status 2."""

import io
import json
from pathlib import Path

import pytest
from django.core.management import call_command
from django.core.management.base import CommandError

from tests.patterns.measured_cases import sequence_document

USE_CASE = (
    Path(__file__).resolve().parents[2] / "hrc/patterns/examples/use_cases/1_spot_taping.json"
)


def _predict(*args: str) -> str:
    out = io.StringIO()
    call_command("predict", *args, stdout=out)
    return out.getvalue()


def test_the_table_names_the_cycle_each_actors_load_and_the_bottleneck() -> None:
    table = _predict(str(USE_CASE), "--cases", "30", "--people", "o=2")

    assert "30 of 30 cases completed" in table
    assert "cycle time  p50" in table
    assert "bottleneck  " in table
    for actor in ("o", "axis", "cL", "cR"):
        assert f"\n{actor} " in table
    assert "critical path of the typical case:" in table


def test_json_is_the_apis_answer(tmp_path: Path) -> None:
    path = tmp_path / "sequence.json"
    path.write_text(json.dumps(sequence_document()))

    answer = json.loads(_predict(str(path), "--cases", "4", "--seed", "7", "--json"))

    assert answer["prediction"]["cases"] == 4
    assert answer["prediction"]["seed"] == 7
    assert answer["prediction"]["cycle_time"]["p50"] == 60  # two operator tasks, 30 s each
    assert answer["durations"]["prep"]["source"] == "assumed"


@pytest.mark.parametrize(
    ("content", "message"),
    [
        ("not json", "not JSON"),
        (json.dumps({"format": "hrc-pattern/1", "processes": 3}), "hrc-pattern/1"),
        (json.dumps({"format": "hrc-pattern/1"}), "structural rules"),
    ],
)
def test_a_file_that_is_not_a_runnable_document_ends_with_status_2(
    tmp_path: Path, content: str, message: str
) -> None:
    path = tmp_path / "bad.json"
    path.write_text(content)

    with pytest.raises(CommandError, match=message) as raised:
        _predict(str(path))

    assert raised.value.returncode == 2


def test_a_missing_file_or_a_bad_option_ends_with_status_2(tmp_path: Path) -> None:
    path = tmp_path / "sequence.json"
    path.write_text(json.dumps(sequence_document()))

    with pytest.raises(CommandError, match="cannot read") as missing:
        _predict(str(tmp_path / "nowhere.json"))
    with pytest.raises(CommandError, match="no operator actor 'x'") as unknown:
        _predict(str(path), "--people", "x=2")
    assert missing.value.returncode == unknown.value.returncode == 2
    # From the shell argparse ends a usage error with status 2; call_command raises instead.
    with pytest.raises(CommandError, match="--cases: invalid whole number from 1 to 10000"):
        call_command("predict", str(path), "--cases", "0")
