"""The XES writer from plain rows: structure, traces, lifecycle, escaping. No database."""

import datetime as dt

import pytest

from hrc.analytics.xes import EventRow, TraceRow, timestamp, traces, write_log
from tests.analytics.xes_structure import NS, check_xes

START = dt.datetime(2025, 3, 1, 8, 0, tzinfo=dt.UTC)


def at(seconds: float) -> dt.datetime:
    return START + dt.timedelta(seconds=seconds)


def event(
    case: int, seq: int, type_: str, task: str, item: int, resource: str = "", **detail: object
) -> EventRow:
    return EventRow(
        case, seq, at(seq), type_, task, f"{task} label", "o", "operator", item, resource, detail
    )


def document(cases: list[TraceRow], events: list[EventRow], lifecycle: str = "pairs") -> str:
    return "".join(write_log([("concept:name", "log")], traces(cases, events, lifecycle)))  # type: ignore[arg-type]


def case(pk: int) -> TraceRow:
    return TraceRow(pk, (("concept:name", str(pk)), ("version", 3)))


def values(event_element: object, key: str) -> str | None:
    for attribute in event_element:  # type: ignore[attr-defined]
        if attribute.attrib["key"] == key:
            return str(attribute.attrib["value"])
    return None


def test_each_case_is_a_trace_and_each_task_a_start_and_complete_pair_in_log_order() -> None:
    events = [
        event(1, 1, "case-started", "", 0),
        event(1, 2, "task-offered", "to1", 10),
        event(1, 3, "task-started", "to1", 10, "olivia"),
        event(1, 4, "task-completed", "to1", 10, "olivia"),
        event(1, 5, "transition-fired", "split", 0),
        event(1, 6, "task-started", "tc1", 11, "ur5e-left"),
        event(1, 7, "task-completed", "tc1", 11, "ur5e-left"),
        event(3, 1, "task-started", "to1", 12),
    ]
    root = check_xes(document([case(1), case(2), case(3)], events))
    found = root.findall(f"{NS}trace")
    assert [values(t, "concept:name") for t in found] == ["1", "2", "3"]
    first = found[0].findall(f"{NS}event")
    assert [(values(e, "task"), values(e, "lifecycle:transition")) for e in first] == [
        ("to1", "start"),
        ("to1", "complete"),
        ("tc1", "start"),
        ("tc1", "complete"),
    ]
    assert [values(e, "org:resource") for e in first] == ["olivia"] * 2 + ["ur5e-left"] * 2
    assert values(first[0], "concept:name") == "to1 label"
    assert values(first[0], "time:timestamp") == "2025-03-01T08:00:03.000+00:00"
    assert values(first[0], "org:role") == "o"
    assert found[1].findall(f"{NS}event") == []  # a case without task events is still a trace
    assert len(found[2].findall(f"{NS}event")) == 1


def test_the_full_lifecycle_adds_schedule_assign_suspend_resume_and_both_aborts() -> None:
    events = [
        event(1, 1, "task-offered", "to1", 10),
        event(1, 2, "task-claimed", "to1", 10, "olivia"),
        event(1, 3, "task-unclaimed", "to1", 10, "olivia"),
        event(1, 4, "task-withdrawn", "to1", 10, why="another task of the choice started"),
        event(1, 5, "task-offered", "tc1", 11),
        event(1, 6, "task-started", "tc1", 11),
        event(1, 7, "task-interrupted", "tc1", 11, interruption=4, mode="pause"),
        event(1, 8, "task-resumed", "tc1", 11, interruption=4),
        event(1, 9, "task-withdrawn", "tc1", 11, why="the case is cancelled"),
    ]
    root = check_xes(document([case(1)], events, "full"))
    rows = root.find(f"{NS}trace").findall(f"{NS}event")  # type: ignore[union-attr]
    assert [values(e, "lifecycle:transition") for e in rows] == [
        "schedule", "assign", "reassign", "withdraw",
        "schedule", "start", "suspend", "resume", "ate_abort",
    ]  # fmt: skip
    assert (values(rows[6], "interruption"), values(rows[6], "mode")) == ("4", "pause")
    assert values(rows[3], "why") == "another task of the choice started"
    pairs = check_xes(document([case(1)], events, "pairs")).findall(f"{NS}trace/{NS}event")
    assert [values(e, "lifecycle:transition") for e in pairs] == ["start"]


def test_text_that_is_not_plain_survives_the_trip_through_xml() -> None:
    label = 'pick "A" & <B>\nthen\tC\x01'
    row = EventRow(1, 1, at(0), "task-started", "t", label, "o", "operator", 5, "ø-user")
    root = check_xes(document([case(1)], [row]))
    (parsed,) = root.find(f"{NS}trace").findall(f"{NS}event")  # type: ignore[union-attr]
    assert values(parsed, "concept:name") == 'pick "A" & <B>\nthen\tC\ufffd'
    assert values(parsed, "org:resource") == "ø-user"


def test_the_document_comes_in_chunks_one_per_trace() -> None:
    chunks = list(write_log([], traces([case(1), case(2)], [])))
    assert len(chunks) == 4  # head, two traces, end
    assert chunks[1].startswith("  <trace>")
    assert chunks[-1] == "</log>\n"


def test_timestamps_are_utc_with_milliseconds_and_must_know_their_zone() -> None:
    vienna = dt.timezone(dt.timedelta(hours=1))
    assert timestamp(dt.datetime(2025, 3, 1, 9, 0, 0, 250000, tzinfo=vienna)) == (
        "2025-03-01T08:00:00.250+00:00"
    )
    with pytest.raises(ValueError, match="time zone"):
        timestamp(dt.datetime(2025, 3, 1, 9, 0))


def test_the_structure_check_catches_an_attribute_before_an_extension() -> None:
    broken = document([case(1)], []).replace(
        '  <extension name="Concept"', '  <string key="x" value="y"/>\n  <extension name="Concept"'
    )
    with pytest.raises(AssertionError, match="too late"):
        check_xes(broken)
