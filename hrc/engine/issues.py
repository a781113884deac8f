"""What a check finds: issues with a stable code, a message a person can act on, and element ids."""

from dataclasses import dataclass, field
from typing import Literal

Severity = Literal["error", "warning"]

# Codes after which the model is not a well-formed set of workflow nets, so
# its behaviour (soundness) cannot be decided. In the order of pattern-format.md.
STRUCTURAL_CODES = (
    "format",
    "duplicate-id",
    "unknown-node",
    "arc-kind",
    "unknown-actor",
    "unassigned-actor",
    "idle-actor",
    "constraint-self",
    "constraint-unperformed",
    "constraint-same-performer",
    "constraint-type",
    "constraint-duplicate",
    "constraint-conflict",
    "no-actors",
    "unassigned-workpiece",
    "not-workflow-net",
)
# task-config: a task, guard or message configuration the runtime could not run (taskconfig.py).
# to-rewrite: a transition or place carries a `rewrite` note, a piece an importer could not
# translate; the model stays a draft until someone rewrites it.
ERROR_CODES = (
    *STRUCTURAL_CODES,
    "task-config",
    "to-rewrite",
    "pattern-mismatch",
    "unsound",
    "unbounded",
)
# state-space-too-large: soundness was not decided within the check's budget (budget.py), its
# markings or its seconds; the message says which ("too large to decide in 2 s").
WARNING_CODES = ("vacuous-pattern", "no-pattern", "state-space-too-large")
CODES = (*ERROR_CODES, *WARNING_CODES)


@dataclass(frozen=True)
class Issue:
    code: str
    message: str
    elements: tuple[str, ...] = ()
    severity: Severity = "error"
    witness: tuple[str, ...] | None = field(default=None, compare=False)
    """For behavioural issues: the firing sequence that shows it (names like `start tc1`)."""

    def as_dict(self) -> dict[str, object]:
        data: dict[str, object] = {
            "code": self.code,
            "message": self.message,
            "elements": list(self.elements),
        }
        if self.witness is not None:
            data["witness"] = list(self.witness)
        return data


def error(code: str, message: str, *elements: str) -> Issue:
    return Issue(code, message, tuple(elements), "error")


def warning(code: str, message: str, *elements: str) -> Issue:
    return Issue(code, message, tuple(elements), "warning")
