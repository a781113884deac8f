"""Reading and writing `hrc-pattern/1`, the one serialization of a collaboration pattern.

`read_pattern` turns parsed JSON into a `Pattern` or raises `FormatError`
with every shape problem it found (code `format`, or `duplicate-id` is left
to the rules: shape only here). `write_pattern` is its inverse; keys this
version does not know travel in each element's `extra` and are written back
unchanged, so a round trip keeps the editor's layout and task configuration.
"""

import json
from collections.abc import Callable, Mapping
from typing import Any, TypeVar, cast

from hrc.engine.issues import Issue, error
from hrc.engine.model import (
    ACTOR_TYPES,
    PATTERN_NAMES,
    Actor,
    ActorType,
    Constraint,
    Pattern,
    Place,
    Process,
    Transition,
)

FORMAT = "hrc-pattern/1"

_T = TypeVar("_T")


class FormatError(Exception):
    """The document is not a readable `hrc-pattern/1`; `issues` says where and why."""

    def __init__(self, issues: list[Issue]) -> None:
        super().__init__("; ".join(issue.message for issue in issues))
        self.issues = issues


def parse_json(text: str | bytes) -> object:
    """Parses JSON text; raises FormatError naming the line and column of a syntax error."""
    try:
        return cast(object, json.loads(text))
    except UnicodeDecodeError:
        raise FormatError([error("format", "The document is not UTF-8 text.")]) from None
    except json.JSONDecodeError as exc:
        message = f"The document is not JSON: {exc.msg} at line {exc.lineno}, column {exc.colno}."
        raise FormatError([error("format", message)]) from None


def loads(text: str | bytes) -> Pattern:
    """Parses and reads a document in one step."""
    return read_pattern(parse_json(text))


def dumps(pattern: Pattern) -> str:
    return json.dumps(write_pattern(pattern), indent=2, ensure_ascii=False)


class _Reader:
    """Collects shape problems instead of stopping at the first, so one answer lists them all."""

    def __init__(self) -> None:
        self.issues: list[Issue] = []

    def fail(self, message: str, *elements: str) -> None:
        self.issues.append(error("format", message, *elements))

    def mapping(self, value: object, where: str, *elements: str) -> Mapping[str, Any] | None:
        if isinstance(value, Mapping) and all(isinstance(k, str) for k in value):
            return value
        self.fail(f"{where} must be a JSON object, got {_kind(value)}.", *elements)
        return None

    def items(
        self,
        data: Mapping[str, Any],
        key: str,
        where: str,
        read: Callable[[object, str], _T | None],
    ) -> list[_T]:
        """Reads the list under `key` (absent means empty) with `read` for each item."""
        path = f"{where}.{key}" if where else key
        value = data.get(key, [])
        if not isinstance(value, list):
            self.fail(f"{path} must be a list, got {_kind(value)}.")
            return []
        read_items = (read(item, f"{path}[{index}]") for index, item in enumerate(value))
        return [item for item in read_items if item is not None]

    def string(
        self, data: Mapping[str, Any], key: str, where: str, *, required: bool = True
    ) -> str | None:
        value = data.get(key)
        if value is None and not required:
            return None
        if isinstance(value, str) and (value or not required):
            return value
        what = "a non-empty string" if required else "a string"
        self.fail(f"{where}.{key} must be {what}, got {_kind(value)}.", *_ids(data))
        return None

    def pattern(self, data: object) -> Pattern | None:
        document = self.mapping(data, "The document")
        if document is None:
            return None
        if document.get("format") != FORMAT:
            self.fail(
                f'The document must say "format": "{FORMAT}", got {_kind(document.get("format"))}.'
            )
            return None
        name = self.string(document, "name", "The document", required=False) or ""
        declared = self.string(document, "declared_pattern", "The document", required=False)
        if declared is not None and declared not in PATTERN_NAMES:
            allowed = ", ".join(PATTERN_NAMES)
            self.fail(f"declared_pattern {declared!r} is not one of {allowed}.")
        actors = self.items(document, "actors", "", self.actor)
        processes = self.items(document, "processes", "", self.process)
        if isinstance(document.get("processes"), list) and not document["processes"]:
            self.fail("The document has no process: a pattern needs at least one Petri net.")
        constraints = self.items(document, "constraints", "", self.constraint)
        if self.issues:
            return None
        return Pattern(
            name=name,
            actors=tuple(actors),
            processes=tuple(processes),
            constraints=tuple(constraints),
            declared_pattern=declared,
            extra=_extra(document, _PATTERN_KEYS),
        )

    def actor(self, value: object, where: str) -> Actor | None:
        data = self.mapping(value, where)
        if data is None:
            return None
        actor_id = self.string(data, "id", where)
        actor_type = data.get("type")
        if actor_type not in ACTOR_TYPES:
            self.fail(
                f'{where}.type must be "cobot" or "operator", got {_kind(actor_type)}.',
                *_ids(data),
            )
            return None
        if actor_id is None:
            return None
        return Actor(actor_id, cast(ActorType, actor_type), _extra(data, _ACTOR_KEYS))

    def process(self, value: object, where: str) -> Process | None:
        data = self.mapping(value, where)
        if data is None:
            return None
        before = len(self.issues)
        process_id = self.string(data, "id", where)
        workpiece = self.string(data, "workpiece", where, required=False)
        actors = self.items(data, "actors", where, self.actor_ref)
        places = self.items(data, "places", where, self.place)
        transitions = self.items(data, "transitions", where, self.transition)
        arcs = self.items(data, "arcs", where, self.arc)
        if process_id is None or len(self.issues) > before:
            return None
        return Process(
            id=process_id,
            workpiece=workpiece,
            actors=tuple(actors),
            places=tuple(places),
            transitions=tuple(transitions),
            arcs=tuple(arcs),
            extra=_extra(data, _PROCESS_KEYS),
        )

    def actor_ref(self, value: object, where: str) -> str | None:
        if isinstance(value, str) and value:
            return value
        self.fail(f"{where} must be an actor id (a non-empty string), got {_kind(value)}.")
        return None

    def place(self, value: object, where: str) -> Place | None:
        data = self.mapping(value, where)
        if data is None:
            return None
        place_id = self.string(data, "id", where)
        tokens = data.get("tokens")
        if tokens is not None and (
            isinstance(tokens, bool) or not isinstance(tokens, int) or tokens < 0
        ):
            self.fail(
                f"{where}.tokens must be a whole number ≥ 0, got {_kind(tokens)}.", *_ids(data)
            )
            return None
        if place_id is None:
            return None
        return Place(place_id, tokens, _extra(data, _PLACE_KEYS))

    def transition(self, value: object, where: str) -> Transition | None:
        data = self.mapping(value, where)
        if data is None:
            return None
        before = len(self.issues)
        transition_id = self.string(data, "id", where)
        performer = self.string(data, "performer", where, required=False)
        label = self.string(data, "label", where, required=False)
        if transition_id is None or len(self.issues) > before:
            return None
        return Transition(transition_id, performer or None, label, _extra(data, _TRANSITION_KEYS))

    def arc(self, value: object, where: str) -> tuple[str, str] | None:
        if (
            isinstance(value, list)
            and len(value) == 2
            and all(isinstance(end, str) and end for end in value)
        ):
            return (value[0], value[1])
        self.fail(f"{where} must be a pair of node ids [from, to], got {_kind(value)}.")
        return None

    def constraint(self, value: object, where: str) -> Constraint | None:
        data = self.mapping(value, where)
        if data is None:
            return None
        before = len(self.issues)
        source = self.string(data, "from", where)
        target = self.string(data, "to", where)
        constraint_type = self.string(data, "type", where)
        if source is None or target is None or constraint_type is None or len(self.issues) > before:
            return None
        return Constraint(source, target, constraint_type, _extra(data, _CONSTRAINT_KEYS))


def read_pattern(data: object) -> Pattern:
    """Reads a parsed `hrc-pattern/1` document; raises FormatError listing every shape problem.

    Only the shape is checked here; the rules of the formal model (ids, arcs,
    performers, constraints) are `rules.check_rules`' job.
    """
    reader = _Reader()
    pattern = reader.pattern(data)
    if pattern is None:
        raise FormatError(reader.issues)
    return pattern


def write_pattern(pattern: Pattern) -> dict[str, Any]:
    """The document for a pattern; `read_pattern(write_pattern(p)) == p`."""
    document: dict[str, Any] = {"format": FORMAT, "name": pattern.name}
    if pattern.declared_pattern is not None:
        document["declared_pattern"] = pattern.declared_pattern
    document.update(pattern.extra)
    document["actors"] = [{"id": a.id, "type": a.type, **a.extra} for a in pattern.actors]
    document["processes"] = [_write_process(p) for p in pattern.processes]
    document["constraints"] = [
        {"from": c.source, "to": c.target, "type": c.type, **c.extra} for c in pattern.constraints
    ]
    return document


def _write_process(process: Process) -> dict[str, Any]:
    data: dict[str, Any] = {"id": process.id}
    if process.workpiece is not None:
        data["workpiece"] = process.workpiece
    data["actors"] = list(process.actors)
    data.update(process.extra)
    data["places"] = [_write_place(p) for p in process.places]
    data["transitions"] = [_write_transition(t) for t in process.transitions]
    data["arcs"] = [[source, target] for source, target in process.arcs]
    return data


def _write_place(place: Place) -> dict[str, Any]:
    data: dict[str, Any] = {"id": place.id}
    if place.tokens is not None:
        data["tokens"] = place.tokens
    data.update(place.extra)
    return data


def _write_transition(transition: Transition) -> dict[str, Any]:
    data: dict[str, Any] = {"id": transition.id}
    if transition.performer is not None:
        data["performer"] = transition.performer
    if transition.label is not None:
        data["label"] = transition.label
    data.update(transition.extra)
    return data


_PATTERN_KEYS = frozenset(
    {"format", "name", "declared_pattern", "actors", "processes", "constraints"}
)
_ACTOR_KEYS = frozenset({"id", "type"})
_PROCESS_KEYS = frozenset({"id", "workpiece", "actors", "places", "transitions", "arcs"})
_PLACE_KEYS = frozenset({"id", "tokens"})
_TRANSITION_KEYS = frozenset({"id", "performer", "label"})
_CONSTRAINT_KEYS = frozenset({"from", "to", "type"})


def _extra(data: Mapping[str, Any], known: frozenset[str]) -> dict[str, Any]:
    return {key: value for key, value in data.items() if key not in known}


def _ids(data: Mapping[str, Any]) -> tuple[str, ...]:
    """The element's id, when it has a usable one, for the issue's element list."""
    element_id = data.get("id")
    return (element_id,) if isinstance(element_id, str) and element_id else ()


def _kind(value: object) -> str:
    """A short description of a JSON value for messages: `null`, `a number (3)`, `"abc"`."""
    if value is None:
        return "nothing"
    if isinstance(value, bool):
        return str(value).lower()
    if isinstance(value, int | float):
        return f"the number {value}"
    if isinstance(value, str):
        shown = value if len(value) <= 40 else value[:37] + "..."
        return f'"{shown}"'
    if isinstance(value, list):
        return f"a list of {len(value)}"
    return "an object"
