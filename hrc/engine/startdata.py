"""What a case is started with: a form made from the pattern's `data`.

A pattern's `data` (taskconfig.initial_data) holds the values every case
starts with: a cycle counter, a box size, a list of spots. The person who
starts a case may change them, one field per key, each typed by its default:
a whole number stays a whole number, a yes/no stays yes/no, a list stays a
list. Nothing here knows of Django; the start form, the API and the tablet's
start card all read these fields and check against them.
"""

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, Literal

FieldKind = Literal["boolean", "integer", "number", "text", "json"]


@dataclass(frozen=True)
class StartField:
    """One key of the pattern's data as a form field."""

    key: str
    kind: FieldKind
    default: Any

    @property
    def title(self) -> str:
        return self.key.replace("_", " ")


def defaults_of(document: object) -> dict[str, Any]:
    """The `data` of an hrc-pattern/1 document (a published one: checked); {} when it has none."""
    data = document.get("data") if isinstance(document, Mapping) else None
    return dict(data) if isinstance(data, Mapping) else {}


def start_fields(defaults: Mapping[str, Any]) -> list[StartField]:
    """One field per key of the pattern's data, in the document's order."""
    return [StartField(key, _kind(value), value) for key, value in defaults.items()]


def start_schema(defaults: Mapping[str, Any]) -> dict[str, Any]:
    """The fields as a JSON Schema object, with each default, for forms made in the browser."""
    properties = {}
    for field in start_fields(defaults):
        schema: dict[str, Any] = {"title": field.title, "default": field.default}
        if field.kind != "json":
            schema["type"] = "string" if field.kind == "text" else field.kind
        properties[field.key] = schema
    return {"type": "object", "properties": properties, "additionalProperties": False}


def check_start_data(defaults: Mapping[str, Any], data: Mapping[str, Any]) -> dict[str, str]:
    """What is wrong with each key of `data` against the defaults' types; empty when it fits.

    A key the pattern's data does not have is the case's own (a pattern
    without `data` reads what its cases bring), so only known keys are checked.
    """
    fields = {field.key: field for field in start_fields(defaults)}
    problems = {}
    for key, value in data.items():
        field = fields.get(key)
        if field is not None and not _fits(field.kind, field.default, value):
            problems[key] = f"{field.title} must be {_WHAT[field.kind]}, not {_shown(value)}."
    return problems


_WHAT: Mapping[FieldKind, str] = {
    "boolean": "yes or no",
    "integer": "a whole number",
    "number": "a number",
    "text": "text",
    "json": "a list or an object like its default",
}


def _kind(value: Any) -> FieldKind:
    if isinstance(value, bool):
        return "boolean"
    if isinstance(value, int):
        return "integer"
    if isinstance(value, float):
        return "number"
    if isinstance(value, str):
        return "text"
    return "json"


def _fits(kind: FieldKind, default: Any, value: Any) -> bool:
    if kind == "boolean":
        return isinstance(value, bool)
    if kind == "integer":
        return isinstance(value, int) and not isinstance(value, bool)
    if kind == "number":
        return isinstance(value, int | float) and not isinstance(value, bool)
    if kind == "text":
        return isinstance(value, str)
    # A list stays a list and an object an object; what is inside is the tasks' business.
    if default is None:
        return True
    return isinstance(value, list) if isinstance(default, list) else isinstance(value, dict)


def _shown(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 40 else text[:37] + "..."
