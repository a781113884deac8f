"""The patterns app's one door to the engine: reading, checking and converting documents.

Every other module of the app goes through these functions, so a change in
the engine's interface is absorbed here.
"""

__all__ = [
    "FileRefused",
    "FormatError",
    "NoExecutionNet",
    "execution_net",
    "from_bpmn",
    "from_pnml",
    "is_publishable",
    "laid_out",
    "looks_like_bpmn",
    "read_draft",
    "starter_document",
    "storage_problem",
    "to_bpmn",
    "to_pnml",
    "validate_storable_document",
]

import math
from collections.abc import Callable, Iterator
from typing import Any

from django.core.exceptions import ValidationError

from hrc.engine import FORMAT, FormatError, read_pattern, write_pattern
from hrc.engine.bpmn import bpmn_to_pattern, is_bpmn
from hrc.engine.bpmn_export import pattern_to_bpmn
from hrc.engine.issues import Issue
from hrc.engine.layout import is_laid_out, lay_out_pattern
from hrc.engine.model import Pattern
from hrc.engine.pnml import pattern_to_pnml, pnml_to_pattern
from hrc.engine.rules import STRUCTURAL_CODES, check_rules
from hrc.engine.tokengame import execution_net_json
from hrc.errors import Invalid

# Deeper than any real pattern document (about 6 levels, plus the editor's layout),
# shallow enough that nothing downstream (json, jsonb, the serializers) recurses too far.
MAX_DEPTH = 64
# What a new process works on until the engineer names it (the editor gives its new processes the same).
DEFAULT_WORKPIECE = "workpiece"

Report = dict[str, Any]
Called = Callable[[list[str]], Pattern | None]
"""What finds the published pattern a BPMN call activity names (hrc.engine.bpmn's `called`)."""


def read_draft(document: object) -> Pattern:
    """Reads a draft; raises FormatError when it is not the shape of `hrc-pattern/1`.

    Only the shape counts: a draft may break the model's rules (duplicate ids,
    an unsound net); the check (hrc.patterns.checking) says what is wrong with it.
    """
    return read_pattern(document)


def is_publishable(report: Report) -> bool:
    """Valid, and soundness was not found lacking (None means it was not decided)."""
    return bool(report.get("valid")) and report.get("sound") is not False


def starter_document(name: str) -> dict[str, Any]:
    """The smallest readable draft: one empty net, for a pattern created without one."""
    return {
        "format": FORMAT,
        "name": name,
        "actors": [],
        "processes": [
            {
                "id": "N",
                "workpiece": DEFAULT_WORKPIECE,
                "actors": [],
                "places": [{"id": "p1"}],
                "transitions": [],
                "arcs": [],
            }
        ],
        "constraints": [],
    }


class NoExecutionNet(Invalid):
    """The document breaks structural rules, so it has no execution net; `issues` says which (400)."""

    code = "no-execution-net"

    def __init__(self, issues: list[Issue]) -> None:
        rules = "; ".join(issue.message for issue in issues)
        super().__init__(
            f"The model breaks structural rules, so it cannot be played: {rules}",
            extra={"errors": [issue.as_dict() for issue in issues]},
        )
        self.issues = issues


class FileRefused(Invalid):
    """A PNML or BPMN file that cannot be imported (400), named as what it is: its issues
    are the importer's, and no `hrc-pattern/1` wording belongs in front of them."""

    code = "file-refused"

    def __init__(self, kind: str, refusal: FormatError) -> None:
        super().__init__(
            f"The {kind} file cannot be imported: {refusal}",
            extra={"errors": [issue.as_dict() for issue in refusal.issues]},
        )
        self.issues = refusal.issues


def from_pnml(text: bytes) -> dict[str, Any]:
    """An `hrc-pattern/1` document from PNML, laid out unless it brings positions for every node.

    Raises FileRefused on bad or hostile XML and on what the reader does not cover.
    """
    try:
        return write_pattern(_drawn(pnml_to_pattern(text)))
    except FormatError as refusal:
        raise FileRefused("PNML", refusal) from None


def from_bpmn(text: bytes, called: Called | None = None) -> dict[str, Any]:
    """An `hrc-pattern/1` document from BPMN 2.0, laid out in its actors' lanes.

    `called` finds the published pattern a call activity names when the file has no
    process of that id (hrc.engine.bpmn). Raises FileRefused naming the elements on bad
    or hostile XML and on what the mapping does not cover.
    """
    try:
        return write_pattern(_drawn(bpmn_to_pattern(text, called)))
    except FormatError as refusal:
        raise FileRefused("BPMN", refusal) from None


def looks_like_bpmn(text: bytes) -> bool:
    """Whether an XML body is BPMN (root `<definitions>` in BPMN's namespace) rather than PNML."""
    return is_bpmn(text)


def to_pnml(document: object) -> str:
    """The PNML text of a stored document; raises FormatError when it is unreadable."""
    return pattern_to_pnml(read_pattern(document))


def to_bpmn(document: object) -> str:
    """The BPMN 2.0 text of a stored document; raises FormatError when BPMN cannot say it."""
    return pattern_to_bpmn(read_pattern(document))


def laid_out(document: object) -> dict[str, Any]:
    """The document with every node placed in its actor's lane; raises FormatError on a bad shape."""
    return write_pattern(lay_out_pattern(read_pattern(document)))


def execution_net(document: object) -> dict[str, Any]:
    """The execution net the token game plays (engine.tokengame).

    Raises FormatError on a bad shape and NoExecutionNet when a structural rule is broken.
    """
    pattern = read_pattern(document)
    broken = [issue for issue in check_rules(pattern) if issue.code in STRUCTURAL_CODES]
    if broken:
        raise NoExecutionNet(broken)
    return execution_net_json(pattern)


def _drawn(pattern: Pattern) -> Pattern:
    return pattern if is_laid_out(pattern) else lay_out_pattern(pattern)


def storage_problem(value: object) -> str | None:
    """Why PostgreSQL's jsonb (or a later reader) would refuse this value; None when it is fine.

    jsonb refuses the NUL character and non-finite numbers, and very deep
    nesting makes readers recurse without bound.
    """
    for item, depth in _walk(value):
        if depth > MAX_DEPTH:
            return f"The JSON is nested more than {MAX_DEPTH} levels deep."
        if isinstance(item, str) and "\x00" in item:
            return "The JSON contains a NUL character (\\u0000), which cannot be stored."
        if isinstance(item, float) and not math.isfinite(item):
            return "The JSON contains a number that is not finite."
    return None


def validate_storable_document(value: object) -> None:
    """Model-field validator: a readable `hrc-pattern/1` document that the database can store."""
    problem = storage_problem(value)
    if problem:
        raise ValidationError(problem)
    try:
        read_draft(value)
    except FormatError as exc:
        raise ValidationError([issue.message for issue in exc.issues]) from None


def _walk(value: object) -> Iterator[tuple[object, int]]:
    """Every value and key inside `value` with its depth, without recursion."""
    stack: list[tuple[object, int]] = [(value, 1)]
    while stack:
        item, depth = stack.pop()
        yield item, depth
        if isinstance(item, dict):
            stack.extend((key, depth) for key in item)
            stack.extend((child, depth + 1) for child in item.values())
        elif isinstance(item, list):
            stack.extend((child, depth + 1) for child in item)
