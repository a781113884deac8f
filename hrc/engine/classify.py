"""Which of the four collaboration patterns (thesis 4.2.1–4.2.4) a model is.

A model can satisfy several at once: a one-process model without any
constraint meets Synchronized, Cooperation and Collaboration alike, which is
true but says nothing, so that case comes with a warning.
"""

from dataclasses import dataclass

from hrc.engine.issues import Issue, error, warning
from hrc.engine.model import Pattern, PatternName

# The constraint type that characterises each single-process pattern.
_CONSTRAINT_OF: dict[PatternName, str] = {
    "synchronized": "time",
    "cooperation": "space",
    "collaboration": "func",
}


@dataclass(frozen=True)
class Classification:
    patterns: tuple[PatternName, ...]
    unmet: dict[PatternName, list[str]]
    """For each pattern that does not hold, its requirements that fail, in words."""
    vacuous: tuple[PatternName, ...]
    """Patterns that hold only because the model has no constraints."""


def classify(pattern: Pattern) -> Classification:
    unmet: dict[PatternName, list[str]] = {
        name: _single_process_unmet(pattern, constraint_type)
        for name, constraint_type in _CONSTRAINT_OF.items()
    }
    unmet["coexistence"] = _coexistence_unmet(pattern)
    holding = tuple(name for name, reasons in unmet.items() if not reasons)
    vacuous = tuple(name for name in holding if name in _CONSTRAINT_OF and not pattern.constraints)
    return Classification(holding, {n: r for n, r in unmet.items() if r}, vacuous)


def classification_issues(pattern: Pattern, result: Classification) -> list[Issue]:
    """The warnings of a classification, and the error when the declared pattern does not hold."""
    issues: list[Issue] = []
    if result.vacuous:
        names = ", ".join(result.vacuous)
        issues.append(
            warning(
                "vacuous-pattern",
                f"The model counts as {names} only because it has no constraints; draw the "
                "constraints between the actors' tasks to say which pattern you mean.",
            )
        )
    if not result.patterns:
        issues.append(
            warning(
                "no-pattern",
                "The model is none of the four patterns: "
                + "; ".join(
                    f"{name}: {', '.join(reasons)}" for name, reasons in result.unmet.items()
                )
                + ".",
            )
        )
    declared = pattern.declared_pattern
    if declared in result.unmet:
        issues.append(
            error(
                "pattern-mismatch",
                f"The model is declared {declared}, but {'; '.join(result.unmet[declared])}"
                + (f" (it is {', '.join(result.patterns)})." if result.patterns else "."),
            )
        )
    return issues


def _actor_types(pattern: Pattern, actor_ids: tuple[str, ...]) -> set[str]:
    return {actor.type for actor_id in actor_ids if (actor := pattern.actor(actor_id))}


def _single_process_unmet(pattern: Pattern, constraint_type: str) -> list[str]:
    reasons = []
    if len(pattern.processes) != 1:
        reasons.append(f"it needs exactly one process, the model has {len(pattern.processes)}")
    actor_ids = tuple(actor_id for p in pattern.processes for actor_id in p.actors)
    types = _actor_types(pattern, actor_ids)
    if "cobot" not in types:
        reasons.append("it needs at least one cobot")
    if "operator" not in types:
        reasons.append("it needs at least one operator")
    others = sorted({c.type for c in pattern.constraints if c.type != constraint_type})
    if others:
        reasons.append(
            f"every constraint must be a {constraint_type} constraint, the model has "
            f"{', '.join(others)} constraints"
        )
    return reasons


def _coexistence_unmet(pattern: Pattern) -> list[str]:
    reasons = []
    processes = pattern.processes
    if len(processes) < 2:
        reasons.append(f"it needs two or more processes, the model has {len(processes)}")
    crowded = [p.id for p in processes if len(p.actors) != 1]
    if crowded:
        reasons.append(f"each process needs exactly one actor, {', '.join(crowded)} do not")
    actor_ids = [actor_id for p in processes for actor_id in p.actors]
    shared = sorted({a for a in actor_ids if actor_ids.count(a) > 1})
    if shared:
        reasons.append(f"the processes must be disjoint, but {', '.join(shared)} work in several")
    # wpassign is total (rule unassigned-workpiece): a process without a workpiece is not
    # counted as disjoint from the others, it breaks Coexistence as it breaks the rule.
    unassigned = [p.id for p in processes if p.workpiece is None or not p.workpiece.strip()]
    if unassigned:
        have = "has" if len(unassigned) == 1 else "have"
        reasons.append(f"each process needs its own workpiece, {', '.join(unassigned)} {have} none")
    workpieces = [p.workpiece for p in processes if p.workpiece and p.id not in unassigned]
    repeated = sorted({w for w in workpieces if workpieces.count(w) > 1})
    if repeated:
        reasons.append(
            f"the processes must be disjoint, but share the workpiece {', '.join(repeated)}"
        )
    types = _actor_types(pattern, tuple(actor_ids))
    if "cobot" not in types:
        reasons.append("it needs at least one cobot")
    if "operator" not in types:
        reasons.append("it needs at least one operator")
    if pattern.constraints:
        reasons.append(f"it allows no constraints, the model has {len(pattern.constraints)}")
    return reasons
