"""The whole check of a pattern document: shape, rules, classification, soundness.

This is what the API, the editor's server checks, `manage.py check_pattern`
and publishing all call, so every one of them gives the same answer.
"""

from dataclasses import dataclass, field
from typing import Any

from hrc.engine.analysis import Analysis, Fault, analyse
from hrc.engine.budget import NO_TIME_LIMIT, Budget
from hrc.engine.classify import classification_issues, classify
from hrc.engine.document import FormatError, read_pattern
from hrc.engine.execution import build_execution_net, constraint_places
from hrc.engine.issues import Issue, error, warning
from hrc.engine.model import Pattern
from hrc.engine.petri import Marking, Net, NetTransition
from hrc.engine.rules import STRUCTURAL_CODES, check_rules
from hrc.engine.taskconfig import config_issues
from hrc.engine.wording import Names, sentence


@dataclass(frozen=True)
class CheckReport:
    valid: bool
    """No error: a correct 7-tuple, its declared pattern holds, sound and bounded."""
    patterns: tuple[str, ...]
    sound: bool | None
    """None when a rule was broken before soundness could be decided, or the space was too large."""
    errors: tuple[Issue, ...]
    warnings: tuple[Issue, ...]
    stats: dict[str, int] = field(default_factory=dict)

    def as_dict(self) -> dict[str, Any]:
        return {
            "valid": self.valid,
            "patterns": list(self.patterns),
            "sound": self.sound,
            "errors": [issue.as_dict() for issue in self.errors],
            "warnings": [issue.as_dict() for issue in self.warnings],
            "stats": dict(self.stats),
        }


def check_document(data: object, budget: Budget = NO_TIME_LIMIT) -> CheckReport:
    """Checks a parsed `hrc-pattern/1` document; a shape problem gives a report, not an exception."""
    try:
        pattern = read_pattern(data)
    except FormatError as exc:
        return CheckReport(False, (), None, tuple(exc.issues), ())
    return check_pattern(pattern, budget)


def report_of(data: object, budget: Budget = NO_TIME_LIMIT) -> dict[str, Any]:
    """check_document's report as JSON-ready data: what an engine worker process returns."""
    return check_document(data, budget).as_dict()


def check_pattern(pattern: Pattern, budget: Budget = NO_TIME_LIMIT) -> CheckReport:
    """The whole check; soundness is decided within `budget`, whose time starts now.

    The phases before the analysis are linear in the size of the document
    (whose size the caller bounds), so only the analysis reads the clock.
    """
    deadline = budget.start()
    issues = check_rules(pattern)
    classification = classify(pattern)
    issues += classification_issues(pattern, classification)
    issues += config_issues(pattern)
    sound: bool | None = None
    stats: dict[str, int] = {}
    if not any(issue.code in STRUCTURAL_CODES for issue in issues):
        net = build_execution_net(pattern)
        analysis = analyse(net, budget, deadline)
        issues += _analysis_issues(pattern, net, analysis, budget)
        sound, stats = analysis.sound, analysis.stats
    errors = tuple(i for i in issues if i.severity == "error")
    warnings = tuple(i for i in issues if i.severity == "warning")
    return CheckReport(not errors, classification.patterns, sound, errors, warnings, stats)


def _analysis_issues(pattern: Pattern, net: Net, analysis: Analysis, budget: Budget) -> list[Issue]:
    explain = _Explainer(pattern, net)
    issues = [explain.fault(fault) for fault in analysis.faults if fault.kind != "dead"]
    dead = [fault for fault in analysis.faults if fault.kind == "dead"]
    if dead:
        issues.append(explain.dead(dead))
    if not analysis.decided and not analysis.faults:
        issues.append(_too_large(analysis, budget))
    return issues


def _too_large(analysis: Analysis, budget: Budget) -> Issue:
    """The warning of an undecided check, naming the limit it ran into."""
    markings = analysis.stats["markings"]
    if analysis.stopped_by == "time" and budget.seconds is not None:
        limit = f"too large to decide in {budget.seconds:g} s: {markings} markings were explored"
    else:
        limit = f"too large to decide: {markings} markings were explored"
    return warning(
        "state-space-too-large",
        f"The model is {limit} without finding a fault, and the check stops there. Split it "
        "into smaller patterns or reduce the parallel branches.",
    )


class _Explainer:
    """Turns faults into messages an engineer can act on, in the pattern's words."""

    def __init__(self, pattern: Pattern, net: Net) -> None:
        self.net = net
        self.transition = {t.id: t for t in net.transitions}
        self.constraint_of = constraint_places(pattern)
        self.names = Names(pattern)

    def fault(self, fault: Fault) -> Issue:
        sequence = self.sequence(fault.witness)
        marking = fault.marking or Marking()
        if fault.kind == "deadlock":
            waits = self.waits(marking)
            message = (
                f"The pattern can get stuck: {sequence}, nothing more can happen and the case "
                f"has not finished (a deadlock). {sentence('; '.join(w for w, _ in waits)) or 'Nothing is waiting.'}"
            )
            elements = [e for _, ends in waits for e in ends]
        elif fault.kind == "improper":
            message, elements = self.left_over(marking)
            message = f"The case can end with work left over: {sequence}, {message}."
        elif fault.kind == "livelock":
            message = (
                f"The case can loop without end: {sequence}, it can no longer reach its end "
                "place, though tasks can still run."
            )
            elements = sorted({self.transition[f].task for f in fault.witness[-3:]})
        else:
            repeat = ", ".join(self.step(f) for f in fault.repeat)
            place = fault.place or "?"
            message = (
                f"{sentence(self.place_words(place))} can collect tokens without limit: "
                f"{sequence}, repeating {repeat} adds tokens there each time."
            )
            issue = error("unbounded", message, self.task_of(place))
            return Issue(
                issue.code,
                issue.message,
                issue.elements,
                witness=self.labels(fault.witness + fault.repeat),
            )
        return Issue(
            "unsound", message, tuple(dict.fromkeys(elements)), witness=self.labels(fault.witness)
        )

    def left_over(self, marking: Marking) -> tuple[str, list[str]]:
        """What an improper end leaves, each place with its count: tokens beside the end
        place's, and tokens on an end place beyond the one a finished case leaves there."""
        final, running = self.net.final, self.net.implicit  # a process ending implicitly runs on
        surplus = sorted(p for p in final if marking.get(p) > final[p] and p not in running)
        left = sorted(
            p for p in marking if p not in final and p not in self.net.ignored and p not in running
        )
        holds = [self.still_holds(p, marking[p]) for p in left]
        elements = [*surplus, *(self.task_of(p) for p in left)]
        if not surplus:
            return f"the end place has its token while {_joined(holds)}", elements
        ends = [
            f"the end {self.names.place(p)} holds {_tokens(marking[p])} where a finished case "
            f"leaves {_tokens(final[p])}"
            for p in surplus
        ]
        return _joined(ends + holds), elements

    def still_holds(self, place: str, count: int) -> str:
        if place.startswith("running:"):
            task = self.names.task(place.split(":", 1)[1])
            return f"{task} is still running" + ("" if count == 1 else f" {count} times")
        return f"{self.names.place(place)} still holds {_tokens(count)}"

    def dead(self, faults: list[Fault]) -> Issue:
        """One issue for every transition that never fires: a task whose start is dead is listed once."""
        dead = {fault.transition for fault in faults}
        never_start, never_complete, never_fire = [], [], []
        for transition in self.net.transitions:
            if transition.id not in dead:
                continue
            if transition.kind == "start":
                never_start.append(transition)
            elif transition.kind == "silent":
                never_fire.append(transition)
            elif f"start:{transition.task}" not in dead:
                never_complete.append(transition)
        parts = []
        if never_start:
            parts.append(f"{self.tasks(never_start)} can never start")
        if never_complete:
            parts.append(f"{self.tasks(never_complete)} can start but never complete")
        if never_fire:
            names = self.names.nodes([t.task for t in never_fire])
            parts.append(f"{names} never {'fires' if len(never_fire) == 1 else 'fire'}")
        message = f"{'; '.join(parts)} in any run of the pattern."
        needs = [
            f"{self.waiting(t)} needs {self.constraint_of[p].needed(self.names.name)}"
            for t in never_start + never_complete
            for p, _ in t.pre
            if p in self.constraint_of
        ]
        if needs:
            message += " " + sentence("; ".join(needs)) + "."
        elements = [t.task for t in never_start + never_complete + never_fire]
        return error("unsound", message[0].upper() + message[1:], *elements)

    def waits(self, marking: Marking) -> list[tuple[str, list[str]]]:
        """What the transitions that hold some of their inputs wait for.

        Those held up by a constraint alone come first and alone, as they are
        the cause an engineer can act on; otherwise every partly enabled
        transition says which places it lacks.
        """
        held_by_constraint, partly_enabled = [], []
        for transition in self.net.transitions:
            missing = [p for p, w in transition.pre if marking.get(p) < w]
            if not missing or len(missing) == len(transition.pre):
                continue
            needs = " and ".join(self.needed(p) for p in missing)
            ends = [transition.task]
            ends += [self.constraint_of[p].first for p in missing if p in self.constraint_of]
            wait = (f"{self.waiting(transition)} waits for {needs}", ends)
            if all(p in self.constraint_of for p in missing):
                held_by_constraint.append(wait)
            else:
                partly_enabled.append(wait)
        return held_by_constraint or partly_enabled

    def needed(self, place: str) -> str:
        if place in self.constraint_of:
            return self.constraint_of[place].needed(self.names.name)
        if place.startswith("running:"):
            return f"{self.names.task(place.split(':', 1)[1])} to be running"
        return f"a token in {self.names.place(place)}"

    def place_words(self, place: str) -> str:
        if place.startswith("running:"):
            return f"the running {self.names.task(place.split(':', 1)[1])}"
        return self.names.place(place)

    def step(self, firing: str) -> str:
        """A firing in words: `“pick insert” starts`."""
        transition = self.transition[firing]
        return self.names.firing(transition.kind, transition.task)

    def waiting(self, transition: NetTransition) -> str:
        """Who waits: `the start of “pick insert”`, `the completion of …`, `split/join t1`."""
        if transition.kind == "start":
            return f"the start of {self.names.task(transition.task)}"
        if transition.kind == "complete":
            return f"the completion of {self.names.task(transition.task)}"
        return self.names.node(transition.task)

    def tasks(self, transitions: list[NetTransition]) -> str:
        return self.names.nodes([t.task for t in transitions])

    def task_of(self, place: str) -> str:
        return place.split(":", 1)[1] if place.startswith("running:") else place

    def labels(self, firings: tuple[str, ...]) -> tuple[str, ...]:
        return tuple(self.transition[f].label for f in firings)

    def sequence(self, firings: tuple[str, ...]) -> str:
        if not firings:
            return "right at the start"
        return "after " + ", ".join(self.step(f) for f in firings)


def _tokens(count: int) -> str:
    return "1 token" if count == 1 else f"{count} tokens"


def _joined(words: list[str]) -> str:
    return words[0] if len(words) == 1 else f"{', '.join(words[:-1])} and {words[-1]}"
