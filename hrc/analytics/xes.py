"""Cases as an XES event log (IEEE 1849-2016) for process-mining tools (ProM, pm4py, Disco).

One trace per case (`concept:name` is the case id), one event per task
lifecycle step from the case's event log, in the log's order: `concept:name`
(the task's label), `lifecycle:transition`, `time:timestamp`, `org:resource`
(the operator's user name or the cobot's name) and `org:role` (the pattern
actor), with the task id under `task`. `pairs` gives each task's start and
complete; `full` adds schedule (offered), assign (claimed), reassign (given
back), suspend and resume (a space constraint's interruption) and withdraw or
ate_abort (withdrawn before or after it started), the standard lifecycle model.

Pure: rows in, text chunks out (a chunk per trace), so a large log streams
without being held in memory. The rows come from hrc.analytics.selectors.
"""

from __future__ import annotations

import datetime as dt
import functools
import re
from collections.abc import Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Literal

XES_NAMESPACE = "http://www.xes-standard.org/"
# The XSD types xes.version as a decimal.
XES_VERSION = "1.0"
EXTENSIONS = (
    ("Concept", "concept", "http://www.xes-standard.org/concept.xesext"),
    ("Lifecycle", "lifecycle", "http://www.xes-standard.org/lifecycle.xesext"),
    ("Time", "time", "http://www.xes-standard.org/time.xesext"),
    ("Organizational", "org", "http://www.xes-standard.org/org.xesext"),
)
CLASSIFIERS = (
    ("Activity", "concept:name"),
    ("Activity_Lifecycle", "concept:name lifecycle:transition"),
    ("Task", "task"),
)

Lifecycle = Literal["pairs", "full"]
LIFECYCLES: tuple[Lifecycle, ...] = ("pairs", "full")
PAIRS = {"task-started": "start", "task-completed": "complete"}
FULL = PAIRS | {
    "task-offered": "schedule",
    "task-claimed": "assign",
    "task-unclaimed": "reassign",  # back to the candidates, for someone else to take
    "task-reassigned": "reassign",  # by a supervisor, to someone or back to the candidates
    "task-interrupted": "suspend",
    "task-resumed": "resume",
    "task-withdrawn": "withdraw",  # "ate_abort" once the task had started
}
EXPORTED_TYPES = tuple(FULL)

Value = str | int | float | bool | dt.datetime
Attribute = tuple[str, Value]

# Every event has these, so classifiers may use them (the standard asks classifier keys
# to be declared global); the values stand in for a missing one.
GLOBAL_EVENT: tuple[Attribute, ...] = (
    ("concept:name", "__INVALID__"),
    ("lifecycle:transition", "complete"),
    ("time:timestamp", dt.datetime(1970, 1, 1, tzinfo=dt.UTC)),
    ("task", "__INVALID__"),
)
GLOBAL_TRACE: tuple[Attribute, ...] = (("concept:name", "__INVALID__"),)


@dataclass(frozen=True)
class TraceRow:
    """A case: its id and what the trace says about it."""

    case_id: int
    attributes: Sequence[Attribute] = ()


@dataclass(frozen=True)
class EventRow:
    """An entry of a case's event log about a task."""

    case_id: int
    seq: int
    at: dt.datetime
    type: str
    task: str
    label: str
    actor: str
    kind: str
    work_item_id: int | None
    resource: str
    detail: Mapping[str, object] = field(default_factory=dict)


def transition_of(event: EventRow, lifecycle: Lifecycle, started: set[int]) -> str | None:
    """The event's lifecycle transition, None when `lifecycle` leaves it out. `started`
    holds the case's work items that have started so far (this adds to it)."""
    transition = (PAIRS if lifecycle == "pairs" else FULL).get(event.type)
    if transition is None:
        return None
    if event.work_item_id is not None:
        if transition == "start":
            started.add(event.work_item_id)
        elif transition == "withdraw" and event.work_item_id in started:
            transition = "ate_abort"
    return transition


def event_attributes(event: EventRow, transition: str) -> list[Attribute]:
    attributes: list[Attribute] = [
        ("concept:name", event.label or event.task),
        ("lifecycle:transition", transition),
        ("time:timestamp", event.at),
    ]
    if event.resource:
        attributes.append(("org:resource", event.resource))
    if event.actor:
        attributes.append(("org:role", event.actor))
    attributes += [("task", event.task), ("seq", event.seq)]
    if event.kind:
        attributes.append(("kind", event.kind))
    if event.work_item_id is not None:
        attributes.append(("work_item", event.work_item_id))
    for key in ("interruption", "mode", "why"):
        value = event.detail.get(key)
        if isinstance(value, str | int) and not isinstance(value, bool):
            attributes.append((key, value))
    return attributes


def traces(
    cases: Iterable[TraceRow], events: Iterable[EventRow], lifecycle: Lifecycle = "pairs"
) -> Iterator[tuple[TraceRow, list[list[Attribute]]]]:
    """Each case with its events' attributes, merging two streams sorted by case id (events
    by case id, then seq). Events of a case not in `cases` are skipped."""
    pending = iter(events)
    event = next(pending, None)
    for case in cases:
        while event is not None and event.case_id < case.case_id:
            event = next(pending, None)
        rows: list[list[Attribute]] = []
        started: set[int] = set()
        while event is not None and event.case_id == case.case_id:
            transition = transition_of(event, lifecycle, started)
            if transition is not None:
                rows.append(event_attributes(event, transition))
            event = next(pending, None)
        yield case, rows


def write_log(
    log_attributes: Sequence[Attribute],
    trace_stream: Iterable[tuple[TraceRow, list[list[Attribute]]]],
) -> Iterator[str]:
    """The XES document in chunks: the header, then one chunk per trace, then the end."""
    head = ['<?xml version="1.0" encoding="UTF-8"?>\n']
    head.append(f'<log xes.version="{XES_VERSION}" xmlns="{XES_NAMESPACE}">\n')
    head += [
        f"  <extension name={_quote(n)} prefix={_quote(p)} uri={_quote(u)}/>\n"
        for n, p, u in EXTENSIONS
    ]
    for scope, defaults in (("trace", GLOBAL_TRACE), ("event", GLOBAL_EVENT)):
        head.append(f'  <global scope="{scope}">\n')
        head += [_attribute(key, value, 4) for key, value in defaults]
        head.append("  </global>\n")
    head += [f"  <classifier name={_quote(n)} keys={_quote(k)}/>\n" for n, k in CLASSIFIERS]
    head += [_attribute(key, value, 2) for key, value in log_attributes]
    yield "".join(head)
    for trace, events in trace_stream:
        chunk = ["  <trace>\n"]
        chunk += [_attribute(key, value, 4) for key, value in trace.attributes]
        for attributes in events:
            chunk.append("    <event>\n")
            chunk += [_attribute(key, value, 6) for key, value in attributes]
            chunk.append("    </event>\n")
        chunk.append("  </trace>\n")
        yield "".join(chunk)
    yield "</log>\n"


def _attribute(key: str, value: Value, indent: int) -> str:
    # The hot loop of a large export: a type lookup, keys quoted once, plain text unescaped.
    kind = _TAGS.get(type(value)) or _tag(value)
    text = value if kind == "string" else _text(value)
    return f"{_INDENT[indent]}<{kind} key={_quoted_key(key)} value={_quote(str(text))}/>\n"


_TAGS = {bool: "boolean", int: "int", float: "float", str: "string", dt.datetime: "date"}
_INDENT = {n: " " * n for n in (2, 4, 6)}


def _tag(value: Value) -> str:
    """The element of a value whose type is a subclass (a bool is an int to Python)."""
    if isinstance(value, bool):
        return "boolean"
    if isinstance(value, int):
        return "int"
    if isinstance(value, float):
        return "float"
    if isinstance(value, dt.datetime):
        return "date"
    return "string"


def _text(value: Value) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, dt.datetime):
        return timestamp(value)
    return str(value)


@functools.lru_cache(maxsize=256)
def _quoted_key(key: str) -> str:
    return _quote(key)


def timestamp(moment: dt.datetime) -> str:
    """xs:dateTime in UTC with milliseconds: 2025-03-01T09:30:00.250+00:00."""
    if moment.tzinfo is None:
        raise ValueError("XES timestamps must know their time zone")
    return moment.astimezone(dt.UTC).isoformat(timespec="milliseconds")


# Characters XML 1.0 does not allow at all (a label pasted from somewhere may hold them).
_NOT_XML = re.compile("[\x00-\x08\x0b\x0c\x0e-\x1f\ud800-\udfff\ufffe\uffff]")
_ESCAPES = {"&": "&amp;", "<": "&lt;", ">": "&gt;", '"': "&quot;"}
# Line breaks and tabs in an attribute value would be read back as spaces unless escaped.
_ESCAPES |= {"\n": "&#10;", "\r": "&#13;", "\t": "&#9;"}
_TO_ESCAPE = re.compile('[&<>"\n\r\t]')
# Either of the above: most text has none and goes out as it is.
_SPECIAL = re.compile(_NOT_XML.pattern[:-1] + '&<>"\n\r\t]')


def _quote(text: str) -> str:
    if _SPECIAL.search(text) is None:
        return f'"{text}"'
    clean = _NOT_XML.sub("\ufffd", text)
    return '"' + _TO_ESCAPE.sub(lambda m: _ESCAPES[m.group()], clean) + '"'
