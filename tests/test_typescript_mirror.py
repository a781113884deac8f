"""The TypeScript copies of the server's constants (frontend/src) say what the Python ones say.

Each copy is read from its `export const` (or `export type` union) as a literal; the payload
types of the live socket have their own mirror test in tests/live/test_events_mirror.py.
"""

from __future__ import annotations

import json
import re
import typing
from collections.abc import Callable
from pathlib import Path

import pytest

from hrc.cases import choices as case_choices
from hrc.cobots import choices as cobot_choices
from hrc.engine import document, model, taskconfig
from hrc.live import events

FRONTEND = Path(__file__).resolve().parent.parent / "frontend" / "src"


def _labels(choices: type[typing.Any]) -> dict[str, str]:
    return {str(value): str(label) for value, label in choices.choices}


def _values(values: typing.Iterable[object]) -> set[str]:
    return {str(value) for value in values}


# (TypeScript file, constant or type name, how to read it, the Python value it copies)
MIRRORS: list[tuple[str, str, Callable[[typing.Any], object], object]] = [
    ("shared/choices.ts", "CASE_STATUSES", dict, _labels(case_choices.CaseStatus)),
    ("shared/choices.ts", "OPEN_CASE_STATUSES", set, _values(case_choices.OPEN_CASE_STATUSES)),
    (
        "shared/choices.ts",
        "OPEN_WORK_ITEM_STATES",
        set,
        _values(case_choices.OPEN_WORK_ITEM_STATES),
    ),
    ("shared/choices.ts", "EVENT_TYPES", dict, _labels(case_choices.EventType)),
    ("shared/choices.ts", "INCIDENT_KINDS", dict, _labels(case_choices.IncidentKind)),
    ("shared/choices.ts", "RESOLUTIONS", list, [str(value) for value in case_choices.Resolution]),
    ("shared/choices.ts", "CONTROL_COMMANDS", dict, _labels(cobot_choices.ControlCommand)),
    ("shared/choices.ts", "COMMAND_OUTCOMES", dict, _labels(cobot_choices.CommandOutcome)),
    ("live/events.ts", "CASE_DELTA_TYPES", set, set(events.CASE_DELTA_TYPES)),
    ("editor/model/document.ts", "FORMAT", str, document.FORMAT),
    ("editor/model/document.ts", "ACTOR_TYPES", list, list(typing.get_args(model.ActorType))),
    (
        "editor/model/document.ts",
        "CONSTRAINT_TYPES",
        list,
        list(typing.get_args(model.ConstraintType)),
    ),
    ("editor/model/document.ts", "PATTERN_NAMES", list, list(typing.get_args(model.PatternName))),
    ("editor/model/taskconfig.ts", "TaskKind", set, set(typing.get_args(taskconfig.TaskKind))),
    ("editor/model/taskconfig.ts", "POSE_LENGTH", int, taskconfig.POSE_LENGTH),
    ("editor/model/taskconfig.ts", "MAX_POSES", int, taskconfig.MAX_POSES),
    ("editor/model/taskconfig.ts", "INTERRUPT_MODES", list, list(taskconfig.INTERRUPT_MODES)),
    (
        "editor/model/taskconfig.ts",
        "SPACE_MODES",
        dict,
        {"+".join(pair): list(modes) for pair, modes in taskconfig.SPACE_MODES.items()},
    ),
    (
        "editor/model/taskconfig.ts",
        "DEVICE_CALLS",
        dict,
        {name: list(arguments) for name, (_, arguments, _) in taskconfig.DEVICE_CALLS.items()},
    ),
]


def read_literal(text: str, name: str) -> object:
    """The literal `name` is defined as in TypeScript `text`, as JSON would read it.

    Reads `export const NAME[: type] = literal;` (an array, `new Set([...])`, an object of
    strings or string arrays, a string, a number) and `export type NAME = "a" | "b";`.
    """
    union = re.search(rf"^export type {name} = ((?:\"[^\"]*\"(?: \| )?)+);$", text, re.M)
    if union:
        return re.findall(r'"([^"]*)"', union.group(1))
    found = re.search(rf"^export const {name}\b[^=]*= (.*?);$", text, re.M | re.S)
    assert found, f"no export const {name}"
    literal = found.group(1).strip()
    literal = re.sub(r"^new Set\((.*)\)$", r"\1", literal, flags=re.S)
    literal = re.sub(r"\s+as const$", "", literal)
    literal = re.sub(r"([{,]\s*)([A-Za-z_]\w*):", r'\1"\2":', literal)  # bare keys
    literal = re.sub(r",(\s*[}\]])", r"\1", literal)  # trailing commas
    return json.loads(literal)


def _read(path: str, name: str, kind: Callable[[typing.Any], object]) -> object:
    return kind(read_literal((FRONTEND / path).read_text(), name))


# By file and name: a set's printed order differs between processes, and xdist's workers must agree.
MIRROR_IDS = [f"{path}:{name}" for path, name, _kind, _python in MIRRORS]


@pytest.mark.parametrize(("path", "name", "kind", "python"), MIRRORS, ids=MIRROR_IDS)
def test_the_typescript_copy_says_what_python_says(
    path: str, name: str, kind: Callable[[typing.Any], object], python: object
) -> None:
    assert _read(path, name, kind) == python


def _sample(python: object) -> str:
    """A value of the Python constant, as the TypeScript copy spells it."""
    if isinstance(python, dict):
        return str(next(iter(python)))
    if isinstance(python, set | list):
        return str(min(python) if isinstance(python, set) else python[0])
    return str(python)


@pytest.mark.parametrize(("path", "name", "kind", "python"), MIRRORS, ids=MIRROR_IDS)
def test_a_changed_value_in_the_copy_is_seen(
    path: str, name: str, kind: Callable[[typing.Any], object], python: object
) -> None:
    text = (FRONTEND / path).read_text()
    start = re.search(rf"^export (?:const|type) {name}\b", text, re.M)
    assert start
    sample = _sample(python)
    at = text.index(sample, start.end())
    changed = text[:at] + ("9" if sample.isdigit() else "X") + text[at + 1 :]
    assert kind(read_literal(changed, name)) != python
