"""The `timer` and `cancels` keys of silent transitions: ISO 8601 durations, cancellation regions."""

from typing import Any

import pytest

from hrc.engine import check_document, read_pattern
from hrc.engine.taskconfig import (
    ConfigError,
    cancels_of,
    config_issues,
    parse_duration,
    timer_of,
)
from tests.engine.builders import document, process
from tests.engine.test_taskconfig import _doc, _silent


@pytest.mark.parametrize(
    ("text", "milliseconds"),
    [
        ("PT5M", 300_000),
        ("PT30S", 30_000),
        ("PT0.5S", 500),
        ("PT0,25S", 250),
        ("P1DT2H", 93_600_000),
        ("PT1H30M", 5_400_000),
        ("P1.5D", 129_600_000),
        ("P2W", 1_209_600_000),
        ("pt5m", 300_000),
        ("PT0S", 0),
    ],
)
def test_a_duration_is_read_in_milliseconds(text: str, milliseconds: int) -> None:
    assert parse_duration(text) == milliseconds


@pytest.mark.parametrize("text", ["P1Y", "P2M", "P1Y2M", "P1MT5S"])
def test_years_and_months_are_refused_as_having_no_fixed_length(text: str) -> None:
    with pytest.raises(ValueError, match="years or months, which have no fixed length"):
        parse_duration(text)


@pytest.mark.parametrize("text", ["", "P", "PT", "P1DT", "5M", "PT1M1H", "-PT5S", "P1W2D", "PT5X"])
def test_what_is_no_iso_duration_is_refused_with_an_example(text: str) -> None:
    with pytest.raises(ValueError, match="is not an ISO 8601 duration such as PT5M"):
        parse_duration(text)


def test_a_timer_longer_than_a_year_is_refused() -> None:
    assert parse_duration("P366D") == 366 * 86_400_000
    with pytest.raises(ValueError, match="longer than a year"):
        parse_duration("P367D")


def test_timer_of_gives_the_duration_or_none() -> None:
    assert timer_of(_silent(timer="PT2M")) == 120_000
    assert timer_of(_silent()) is None


@pytest.mark.parametrize(
    ("timer", "complaint"),
    [
        (300, "'timer' must be an ISO 8601 duration"),
        ("P1M", "'timer': 'P1M' counts years or months"),
        ("five minutes", "'timer': 'five minutes' is not an ISO 8601 duration"),
    ],
)
def test_a_malformed_timer_is_a_config_error_naming_the_transition(
    timer: object, complaint: str
) -> None:
    with pytest.raises(ConfigError, match=f"^x1: {complaint}"):
        timer_of(_silent(timer=timer))
    [issue] = config_issues(read_pattern(_doc(x1={"timer": timer})))
    assert (issue.code, issue.elements) == ("task-config", ("x1",))
    assert complaint in issue.message


@pytest.mark.parametrize("key", ["timer", "cancels"])
def test_a_task_has_no_timer_and_cancels_nothing(key: str) -> None:
    value: Any = "PT5M" if key == "timer" else ["p2"]

    [issue] = config_issues(read_pattern(_doc(tc1={key: value})))

    assert issue.elements == ("tc1",)
    assert f"only silent transitions have a '{key}'" in issue.message


@pytest.mark.parametrize(
    ("other", "complaint"),
    [
        ({"guard": "data.ok"}, "waits for a timer or has a guard, not both"),
        ({"message": {"name": "go"}}, "waits for a timer or a message, not both"),
    ],
)
def test_a_timer_goes_with_neither_guard_nor_message(other: dict[str, Any], complaint: str) -> None:
    [issue] = config_issues(read_pattern(_doc(x1={"timer": "PT5M", **other})))

    assert issue.elements == ("x1",)
    assert complaint in issue.message


def _two_processes(**cancels: Any) -> dict[str, Any]:
    """N: p1 tc1 p2 x1 p3 to1 p4; M: pq1 u1 pq2 to2 pq3; `cancels` goes on x1."""
    data = document(
        process("N", "p1 tc1 p2 x1 p3 to1 p4", performers={"tc1": "c", "to1": "o"}),
        process("M", "pq1 u1 pq2 to2 pq3", performers={"to2": "o2"}, workpiece="w2"),
    )
    data["processes"][0]["transitions"][1].update(cancels)
    return data


def test_cancels_lists_places_and_transitions_of_its_own_process() -> None:
    pattern = read_pattern(_two_processes(cancels=["p4", "tc1", "to1", "x1", "p4"]))
    process, x1 = pattern.processes[0], pattern.transition("x1")
    assert x1 is not None

    assert cancels_of(process, x1) == ("p4", "tc1", "to1", "x1")
    assert config_issues(pattern) == []


@pytest.mark.parametrize(
    ("cancels", "complaint"),
    [
        ("p4", "'cancels' must be a list of place and task ids"),
        ({"p4": True}, "'cancels' must be a list of place and task ids"),
        (["p4", 3], "'cancels' must be a list of place and task ids"),
        (["p9"], "names 'p9', which is no place or task of its process N"),
        (["to2", "pq2"], "names 'to2', 'pq2', which are no place or task of its process N"),
    ],
)
def test_a_wrong_cancels_is_a_config_error(cancels: object, complaint: str) -> None:
    report = check_document(_two_processes(cancels=cancels))

    [issue] = [e for e in report.errors if e.code == "task-config"]
    assert issue.elements == ("x1",)
    assert complaint in issue.message
    # The soundness is still decided, as without the key.
    assert report.sound is True
