"""An operator's answers checked against their task's form (a JSON Schema object)."""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from typing import Any

import jsonschema


def form_problems(
    form: Mapping[str, Any] | None, answers: Mapping[str, Any]
) -> dict[str, list[str]]:
    """What the form refuses, by field ("the form" for the whole); empty when it accepts them.

    A missing required answer is named by its own field, not reported against the form as a
    whole. Nothing is filled in: the answers are stored as given.
    """
    if form is None:
        return {}
    validator = jsonschema.Draft202012Validator(form)
    fields: dict[str, list[str]] = {}
    for problem in sorted(validator.iter_errors(answers), key=lambda e: list(e.absolute_path)):
        for name, message in _problems(problem):
            fields.setdefault(name, []).append(message)
    return fields


def _problems(problem: jsonschema.ValidationError) -> list[tuple[str, str]]:
    path = list(problem.absolute_path)
    if problem.validator == "required" and isinstance(problem.instance, Mapping):
        return [
            (_field([*path, name]), "an answer is required")
            for name in problem.validator_value
            if name not in problem.instance
        ]
    return [(_field(path), problem.message)]


def _field(path: Iterable[Any]) -> str:
    return ".".join(str(part) for part in path) or "the form"
