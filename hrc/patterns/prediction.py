"""Predicting a document before it runs (issue 22): the scenario built from the engineer's
options and the plant's measured times, then hrc.engine.prediction's simulation. Reads only.

Each task's time comes from, in this order: the engineer's (`durations`), the times
measured in the pattern's earlier versions' completed cases (matched by task id, else by
label, so a renamed id keeps its history), the program's simulated time (the simulator's
plant, for cobot and device tasks), else the engine's default; the answer says which.
Choices follow the engineer's weights, else how often each branch was taken.

The measurements are hrc.analytics' (which reads hrc.cases, above this app): it registers
its reader with `measure_with` when Django starts, so this module imports nothing above it.
"""

from __future__ import annotations

import math
from collections import defaultdict
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from typing import Any, Final, Literal, TypeVar

from hrc.engine.durations import Duration, DurationError, Empirical, Fixed, Lognormal, fit
from hrc.engine.model import Pattern
from hrc.engine.prediction import Scenario, predict
from hrc.engine.prediction_report import Prediction
from hrc.engine.rules import STRUCTURAL_CODES, check_rules
from hrc.engine.runtime import CaseNet
from hrc.errors import Invalid
from hrc.patterns.documents import NoExecutionNet, read_draft
from hrc_gateway.sim.timing import SimulatedPlant

# How much a request may simulate: 10,000 cases of the largest use case take about 2 s of
# CPU, which the request holds an engine slot for.
MAX_CASES: Final = 10_000
MAX_PARALLEL: Final = 1000

Source = Literal["given", "measured", "program", "assumed"]


@dataclass(frozen=True)
class Measured:
    """What a pattern's earlier versions' completed cases tell: each task's work times (seconds)
    by task id and by label, and how often each silent transition fired. `transitions`: the
    silent transitions those versions had (a branch among them with no firing was never
    taken); None when the log did not say."""

    by_task: Mapping[str, Sequence[float]] = field(default_factory=dict)
    by_label: Mapping[str, Sequence[float]] = field(default_factory=dict)
    fired: Mapping[str, int] = field(default_factory=dict)
    transitions: frozenset[str] | None = None


NOTHING_MEASURED: Final = Measured()

Measure = Callable[[Any], Measured]
"""The measurements of a pattern (a PatternModel the caller may see)."""
_measure: list[Measure] = []
_V = TypeVar("_V")


def measure_with(measure: Measure) -> None:
    """Registers the reader of measured times (hrc.analytics does, when its app is ready)."""
    _measure[:] = [measure]


def measured_for(pattern: Any) -> Measured:
    """The registered reader's measurements of `pattern`; none when no reader is registered."""
    return _measure[0](pattern) if _measure else NOTHING_MEASURED


@dataclass(frozen=True)
class Options:
    """The engineer's options, validated (the API's serializer, the command's arguments)."""

    cases: int = 1000
    parallel: int = 1
    seed: int = 0
    people: Mapping[str, int] = field(default_factory=dict)
    durations: Mapping[str, Duration] = field(default_factory=dict)
    weights: Mapping[str, float] = field(default_factory=dict)
    measured: bool = True


@dataclass(frozen=True)
class TaskTime:
    """Where one task's time came from, as the answer reports it."""

    source: Source
    label: str
    actor: str
    duration: Duration | None
    runs: int | None = None
    """Measured times it was fitted to."""
    matched_by: Literal["id", "label"] | None = None
    simulated_mean: float | None = None
    """The mean of the program's simulated times over the prediction's runs."""

    def as_dict(self) -> dict[str, Any]:
        return {
            "source": self.source,
            "label": self.label,
            "actor": self.actor,
            "describe": self.describe(),
            "distribution": None if self.duration is None else _distribution(self.duration),
            "runs": self.runs,
            "matched_by": self.matched_by,
        }

    def describe(self) -> str:
        if self.duration is None:
            mean = self.simulated_mean
            return "the program's simulated time" + (
                "" if mean is None else f", mean {_seconds(mean)}"
            )
        text = describe(self.duration)
        if self.source == "assumed":
            text += " (the default)"
        if self.runs is not None:
            text += f" ({self.runs} run{'s' if self.runs != 1 else ''}"
            text += ", matched by label)" if self.matched_by == "label" else ")"
        return text


@dataclass(frozen=True)
class Predicted:
    prediction: Prediction
    times: Mapping[str, TaskTime]

    def as_dict(self) -> dict[str, Any]:
        prediction = self.prediction.as_dict()
        del prediction["trace"]
        return {
            "prediction": prediction,
            "durations": {task: time.as_dict() for task, time in self.times.items()},
        }


def predict_document(
    document: object, options: Options, measured: Measured | None = None, *, compared: bool = False
) -> Predicted:
    """Predicts `document` under `options`, with `measured` times where the options give none.

    A version `compared` with the draft the options were written for takes those that name
    its tasks and actors, and leaves the draft's others aside.

    Raises FormatError (not the shape of hrc-pattern/1), NoExecutionNet (a structural rule
    broken: the document cannot run), Invalid (an option names no task or actor of the
    document, or a case variant of its `simulation` is wrong)."""
    pattern = read_draft(document)
    broken = [issue for issue in check_rules(pattern) if issue.code in STRUCTURAL_CODES]
    if broken:
        raise NoExecutionNet(broken)
    unknown = _unknown_names(pattern, options)
    if compared:
        lacked = {name: names for name, (names, _) in unknown.items()}
        options = replace(
            options,
            durations=_without(options.durations, lacked.get("durations")),
            weights=_without(options.weights, lacked.get("weights")),
            people=_without(options.people, lacked.get("people")),
        )
    elif unknown:
        fields = {
            name: [f"The document has no {what} {', '.join(map(repr, sorted(names)))}."]
            for name, (names, what) in unknown.items()
        }
        raise Invalid("; ".join(m for ms in fields.values() for m in ms), fields)
    net = CaseNet(pattern)
    if measured is None or not options.measured:
        measured = NOTHING_MEASURED
    times = _task_times(pattern, options, measured)
    scenario = Scenario(
        cases=options.cases,
        parallel=options.parallel,
        seed=options.seed,
        durations={t: time.duration for t, time in times.items() if time.duration is not None},
        people=dict(options.people),
        weights=_measured_weights(pattern, measured) | dict(options.weights),
    )
    try:
        prediction = predict(net, scenario, plant=SimulatedPlant)
    except ValueError as exc:  # a case variant of the document's "simulation"
        raise Invalid(f"The document's simulation cases are wrong: {exc}") from None
    return Predicted(prediction, _with_defaults(times, pattern, prediction))


def _unknown_names(pattern: Pattern, options: Options) -> dict[str, tuple[set[str], str]]:
    """Option → (the names it gives that the pattern lacks, what they should name)."""
    tasks = {t.id for _, t in pattern.transitions() if t.is_task}
    silent = {t.id for _, t in pattern.transitions() if not t.is_task}
    operators = {a.id for a in pattern.actors if a.type == "operator"}
    unknown = {}
    for name, given, known, what in (
        ("durations", options.durations, tasks, "task"),
        ("weights", options.weights, tasks | silent, "transition"),
        ("people", options.people, operators, "operator actor"),
    ):
        missing = set(given) - known
        if missing:
            unknown[name] = (missing, what)
    return unknown


def _without(given: Mapping[str, _V], names: set[str] | None) -> dict[str, _V]:
    return {name: value for name, value in given.items() if name not in (names or ())}


def _task_times(pattern: Pattern, options: Options, measured: Measured) -> dict[str, TaskTime]:
    times = {}
    for _, task in pattern.transitions():
        if not task.is_task:
            continue
        label, actor = task.label or task.id, task.performer or ""
        given = options.durations.get(task.id)
        if given is not None:
            times[task.id] = TaskTime("given", label, actor, given)
            continue
        samples, matched_by = _samples(task.id, task.label, measured)
        if samples:
            try:
                duration = fit(samples)
            except DurationError:  # no usable time among them
                duration = None
            if duration is not None:
                times[task.id] = TaskTime(
                    "measured", label, actor, duration, len(samples), matched_by
                )
                continue
        times[task.id] = TaskTime("program", label, actor, None)  # settled after the run
    return times


def _samples(
    task: str, label: str | None, measured: Measured
) -> tuple[Sequence[float], Literal["id", "label"] | None]:
    if measured.by_task.get(task):
        return measured.by_task[task], "id"
    if label and measured.by_label.get(label):
        return measured.by_label[label], "label"
    return (), None


def _with_defaults(
    times: Mapping[str, TaskTime], pattern: Pattern, prediction: Prediction
) -> dict[str, TaskTime]:
    """Tasks without a given or measured time: timed by the plant ("program") unless the
    prediction had to take its default ("assumed", an operator's task always)."""
    assumed = set(prediction.assumed)
    types = {actor.id: actor.type for actor in pattern.actors}
    means = {load.task: load.mean_duration for load in prediction.tasks}
    settled = {}
    for task, time in times.items():
        if time.source == "program" and (task in assumed or types.get(time.actor) == "operator"):
            default = _default_of(types.get(time.actor))
            time = TaskTime("assumed", time.label, time.actor, default)
        elif time.source == "program":
            time = TaskTime("program", time.label, time.actor, None, simulated_mean=means.get(task))
        settled[task] = time
    return settled


def _default_of(actor_type: str | None) -> Duration:
    scenario = Scenario()
    return scenario.operator_default if actor_type == "operator" else scenario.cobot_default


def _measured_weights(pattern: Pattern, measured: Measured) -> dict[str, float]:
    """Each choice's branches weighted by how often they were taken, for choices (silent
    transitions sharing an input place) whose every branch the earlier versions had and
    took at least once in all."""
    if measured.transitions is None:
        return {}
    weights: dict[str, float] = {}
    for process in pattern.processes:
        silent = {t.id for t in process.transitions if not t.is_task}
        branches: defaultdict[str, list[str]] = defaultdict(list)
        for source, target in process.arcs:
            if target in silent:
                branches[source].append(target)
        for choice in branches.values():
            if len(choice) < 2 or not set(choice) <= measured.transitions:
                continue
            counts = {t: float(measured.fired.get(t, 0)) for t in choice}
            if sum(counts.values()) > 0:
                weights.update(counts)
    return weights


def describe(duration: Duration) -> str:
    """A distribution as a person reads it: "lognormal, median 4.2 s"."""
    if isinstance(duration, Fixed):
        return f"fixed, {_seconds(duration.seconds)}"
    if isinstance(duration, Lognormal):
        return f"lognormal, median {_seconds(duration.median)}"
    if isinstance(duration, Empirical):
        return f"measured times, mean {_seconds(duration.mean)}"
    return (
        f"triangular, {_number(duration.low)} to {_number(duration.high)} s, "
        f"mostly {_seconds(duration.mode)}"
    )


def _distribution(duration: Duration) -> dict[str, Any]:
    if isinstance(duration, Empirical):  # the samples stay here: the answer gives their mean
        return {"kind": "empirical", "count": len(duration.samples), "mean": duration.mean}
    return duration.as_dict()


def _seconds(value: float) -> str:
    return f"{_number(value)} s"


def _number(value: float) -> str:
    if math.isfinite(value) and value == round(value):
        return str(int(value))
    return f"{value:.3g}" if abs(value) < 100 else f"{value:.0f}"
