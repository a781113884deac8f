"""An operator's answers checked against their task's form (a JSON Schema object), and the
answers a simulated operator gives (`example_answers`)."""

from __future__ import annotations

import math
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


def example_answers(form: Mapping[str, Any] | None, nth: int = 0) -> dict[str, Any]:
    """What a simulated operator enters the `nth` time (from 0) it completes a task with this
    form: for each required field its `examples` in turn (examples[nth mod len]), else its
    first `enum` value, its `default`, or a value of its type; nested objects alike.

    `run_pattern --simulate`'s operators and the prediction both answer by this rule, so a
    prediction takes the branches a simulated run takes."""
    if not form:
        return {}
    properties = form.get("properties", {})
    return {
        name: _example_value(properties.get(name, {}), nth) for name in form.get("required", [])
    }


def answer_period(form: Mapping[str, Any] | None) -> int:
    """After how many completions `example_answers` repeats itself: the least common multiple of
    the lengths of the required fields' examples (1 when none has any)."""
    if not form:
        return 1
    period = 1
    properties = form.get("properties", {})
    for name in form.get("required", []):
        schema = properties.get(name, {})
        examples = schema.get("examples")
        if isinstance(examples, list) and examples:
            period = math.lcm(period, len(examples))
        elif "enum" not in schema and "default" not in schema and schema.get("type") == "object":
            period = math.lcm(period, answer_period(schema))
    return period


def _example_value(schema: Mapping[str, Any], nth: int) -> Any:
    examples = schema.get("examples")
    if isinstance(examples, list) and examples:
        return examples[nth % len(examples)]
    if "enum" in schema:
        return schema["enum"][0]
    if "default" in schema:
        return schema["default"]
    kind = schema.get("type")
    if kind == "boolean":
        return True
    if kind in ("integer", "number"):
        return schema.get("minimum", 0)
    if kind == "array":
        return []
    if kind == "object":
        return example_answers(schema, nth)
    return "ok"
