"""The WebSocket's payloads are typed twice, in hrc/live/events.py and frontend/src/live/events.ts:
the two must name the same types with the same fields."""

from __future__ import annotations

import re
import typing
from pathlib import Path

from django.conf import settings

from hrc.live import events

TS_FILE = Path(settings.BASE_DIR) / "frontend" / "src" / "live" / "events.ts"
_INTERFACE = re.compile(r"export interface (\w+) \{(.*?)\n\}", re.S)
_FIELD = re.compile(r"^\s*(\w+)\??: (.+?);", re.M)
_PY_TO_TS = {"int": "number", "float": "number", "str": "string", "bool": "boolean"}


def _typescript() -> dict[str, dict[str, str]]:
    text = TS_FILE.read_text()
    return {
        name: {field: kind.strip() for field, kind in _FIELD.findall(body)}
        for name, body in _INTERFACE.findall(text)
    }


def _as_typescript(annotation: object) -> str:
    """The TypeScript spelling of a TypedDict field's type, as events.ts writes it."""
    origin = typing.get_origin(annotation)
    arguments = typing.get_args(annotation)
    if origin is typing.Literal:
        return " | ".join(f'"{value}"' for value in arguments)
    if origin in (typing.Union, __import__("types").UnionType):
        return " | ".join("null" if a is type(None) else _as_typescript(a) for a in arguments)
    if origin is list:
        return f"{_as_typescript(arguments[0])}[]"
    if origin is dict:
        return f"Record<{_as_typescript(arguments[0])}, {_as_typescript(arguments[1])}>"
    if isinstance(annotation, type):
        return _PY_TO_TS.get(annotation.__name__, annotation.__name__)
    raise AssertionError(f"no TypeScript spelling for {annotation!r}")


def _python() -> dict[str, dict[str, str]]:
    found = {}
    for name, value in vars(events).items():
        if isinstance(value, type) and typing.is_typeddict(value):
            hints = typing.get_type_hints(value)
            found[name] = {field: _as_typescript(kind) for field, kind in hints.items()}
    return found


def test_every_payload_type_has_the_same_fields_in_typescript() -> None:
    assert _typescript() == _python()


def test_the_union_names_the_same_event_types() -> None:
    union = re.search(r"export type LiveEvent =(.*?);", TS_FILE.read_text(), re.S)
    assert union is not None
    in_typescript = {name.strip() for name in union.group(1).split("|") if name.strip()}
    in_python = {member.__name__ for member in typing.get_args(events.LiveEvent)}
    assert in_typescript == in_python
    literals = {
        typing.get_type_hints(m)["type"].__args__[0] for m in typing.get_args(events.LiveEvent)
    }
    assert literals == {"snapshot", "case", "work-item", "incident", "timer", "cobot-state", "cobot-queue",
                        "cell-stop", "refused"}  # fmt: skip
