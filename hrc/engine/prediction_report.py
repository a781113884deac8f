"""What a prediction (prediction.py) reports: frozen dataclasses, each with `as_dict()` giving
plain JSON values for the API, and the statistics that fill them.

Times are seconds of simulated time. A case's cycle time runs from its start to its end;
the span is from the first case's start to the last case's end.
"""

from __future__ import annotations

import heapq
import math
from collections.abc import Sequence
from dataclasses import asdict, dataclass
from typing import TYPE_CHECKING, Any, Final, Literal

from hrc.engine.prediction_state import CaseState, Resource, WorkItem
from hrc.engine.runtime import CaseNet

if TYPE_CHECKING:
    from hrc.engine.prediction import Scenario

ResourceKind = Literal["operator", "cobot", "device"]
# Stuck cases described one by one in a prediction; the rest are counted.
MAX_STUCK_LISTED: Final = 20


@dataclass(frozen=True)
class Spread:
    """A sample's mean and percentiles (linear between the nearest ranks)."""

    count: int
    mean: float
    p50: float
    p90: float
    p99: float
    min: float
    max: float

    @classmethod
    def of(cls, values: Sequence[float]) -> Spread | None:
        """None for no values."""
        if not values:
            return None
        ordered = sorted(values)
        return cls(
            len(ordered),
            math.fsum(ordered) / len(ordered),
            percentile(ordered, 0.5),
            percentile(ordered, 0.9),
            percentile(ordered, 0.99),
            ordered[0],
            ordered[-1],
        )

    def as_dict(self) -> dict[str, Any]:
        return asdict(self)


def percentile(ordered: Sequence[float], q: float) -> float:
    """The q-quantile (0 ≤ q ≤ 1) of sorted values, interpolated between the nearest ranks."""
    position = q * (len(ordered) - 1)
    low = math.floor(position)
    high = min(low + 1, len(ordered) - 1)
    return ordered[low] + (ordered[high] - ordered[low]) * (position - low)


@dataclass(frozen=True)
class ActorLoad:
    """One operator team, cobot or device over the span.

    `utilisation`: the busy share of the span, per person for a team (busy person-seconds over
    people × span); for a team of unlimited people, the mean number of people busy. A cobot is
    busy while a step of it runs (paused and slowed time included), not while it only holds a
    part for a func constraint (`held_seconds`). `waiting_seconds`: how long its work items
    waited between being offered and starting, in all (for a cobot: jobs in its queue; for a
    team: tasks no free person took, or that a shared area kept out); `waiting_per_case` is
    that over the cases that ran.
    """

    actor: str
    kind: ResourceKind
    people: int | None
    utilisation: float
    busy_seconds: float
    held_seconds: float
    interrupted_seconds: float
    waiting_seconds: float
    waiting_per_case: float
    waited: int
    """Work items that waited at all."""
    work_items: int

    def as_dict(self) -> dict[str, Any]:
        return asdict(self)


@dataclass(frozen=True)
class TaskLoad:
    """One task over every run of it. `critical_seconds`: its mean time per completed case on
    that case's critical path (waiting and working), `critical_share` that over the mean cycle
    time."""

    task: str
    label: str
    actor: str
    runs: int
    mean_duration: float
    """From start to completion (a func constraint's hold included)."""
    mean_wait: float
    """From being offered to starting."""
    critical_seconds: float
    critical_wait_seconds: float
    critical_share: float

    def as_dict(self) -> dict[str, Any]:
        return asdict(self)


@dataclass(frozen=True)
class PathStep:
    """A task on a case's critical path, its times from the case's start. `waited` and
    `worked` are its part of the path: from being offered to starting, and from starting to
    the moment the next task on the path was offered (or the case ended)."""

    task: str
    label: str
    actor: str
    offered: float
    started: float
    completed: float
    waited: float
    worked: float

    def as_dict(self) -> dict[str, Any]:
        return asdict(self)


@dataclass(frozen=True)
class StuckCase:
    """A case that could not end: where it stood, and why, as a person says it."""

    case: int
    at: float
    """Seconds after the case's start."""
    marking: dict[str, int]
    why: str

    def as_dict(self) -> dict[str, Any]:
        return {"case": self.case, "at": self.at, "marking": dict(self.marking), "why": self.why}


@dataclass(frozen=True)
class TraceEvent:
    case: int
    at: float
    """Seconds after the case's start."""
    event: Literal["start", "complete"]
    task: str

    def as_dict(self) -> dict[str, Any]:
        return asdict(self)


@dataclass(frozen=True)
class Prediction:
    """What running `cases` cases, `parallel` at a time, would give.

    `bottleneck`: the task with the most time on the cases' critical paths (its waiting
    included): the one whose shortening, or whose actor's queue's, shortens a cycle most.
    `critical_path`: the typical case's (the completed case whose cycle time is nearest the
    median). `assumed`: tasks no time was given for, timed by the scenario's default.
    """

    cases: int
    completed: int
    parallel: int
    seed: int
    cycle_time: Spread | None
    throughput_per_hour: float
    span_seconds: float
    actors: tuple[ActorLoad, ...]
    tasks: tuple[TaskLoad, ...]
    bottleneck: str | None
    typical_case: int | None
    critical_path: tuple[PathStep, ...]
    stuck: tuple[StuckCase, ...]
    """The first cases that could not end (at most prediction_run.MAX_STUCK_LISTED)."""
    stuck_count: int
    events: int
    assumed: tuple[str, ...]
    trace: tuple[TraceEvent, ...] = ()

    def actor(self, actor: str) -> ActorLoad:
        """The load of one actor (its stand-in's name); KeyError when none ran work."""
        for load in self.actors:
            if load.actor == actor:
                return load
        raise KeyError(actor)

    def task(self, task: str) -> TaskLoad:
        """The load of one task; KeyError when it never ran."""
        for load in self.tasks:
            if load.task == task:
                return load
        raise KeyError(task)

    def as_dict(self) -> dict[str, Any]:
        return {
            "cases": self.cases,
            "completed": self.completed,
            "parallel": self.parallel,
            "seed": self.seed,
            "cycle_time": None if self.cycle_time is None else self.cycle_time.as_dict(),
            "throughput_per_hour": self.throughput_per_hour,
            "span_seconds": self.span_seconds,
            "actors": [load.as_dict() for load in self.actors],
            "tasks": [load.as_dict() for load in self.tasks],
            "bottleneck": self.bottleneck,
            "typical_case": self.typical_case,
            "critical_path": [step.as_dict() for step in self.critical_path],
            "stuck": [case.as_dict() for case in self.stuck],
            "stuck_count": self.stuck_count,
            "events": self.events,
            "assumed": list(self.assumed),
            "trace": [event.as_dict() for event in self.trace],
        }


class Tally:
    """What a simulation counts as it goes, and the prediction made of it at the end."""

    def __init__(self, net: CaseNet) -> None:
        self.net = net
        self.cycle_times: list[tuple[float, int]] = []  # (cycle time, case)
        # The running median of the cycle times: the lower half (negated) and the upper half.
        self.lower: list[float] = []
        self.upper: list[float] = []
        # The typical case: (its cycle time, index, end, critical path) — the completed case
        # nearest the median of the cycle times so far. Only it is kept: keeping every case's
        # work items would give the collector a heap of them to walk.
        self.typical: tuple[float, int, float, list[WorkItem]] | None = None
        # Task → [wait, work] on critical paths; [completions, seconds from start to
        # completion, seconds waited from offer to start].
        self.critical: dict[str, list[float]] = {task: [0.0, 0.0] for task in net.tasks}
        self.tasks: dict[str, list[float]] = {task: [0.0, 0.0, 0.0] for task in net.tasks}
        self.last_end = 0.0  # when the latest case ended: the span runs to there
        self.stuck_cases: list[StuckCase] = []
        self.stuck_count = 0
        self.trace: list[TraceEvent] = []

    def completed(self, case: CaseState, now: float) -> None:
        self.last_end = now
        cycle = now - case.started
        self.cycle_times.append((cycle, case.index))
        path = self._critical_path(case, now)
        median = self._running_median(cycle)
        if self.typical is None or abs(cycle - median) < abs(self.typical[0] - median):
            self.typical = (cycle, case.index, now, path)

    def _running_median(self, value: float) -> float:
        lower, upper = self.lower, self.upper
        if lower and value > -lower[0]:
            heapq.heappush(upper, value)
        else:
            heapq.heappush(lower, -value)
        if len(lower) > len(upper) + 1:
            heapq.heappush(upper, -heapq.heappop(lower))
        elif len(upper) > len(lower):
            heapq.heappush(lower, -heapq.heappop(upper))
        return -lower[0]

    def stuck(self, case: CaseState, now: float, why: str) -> None:
        self.last_end = now
        self.stuck_count += 1
        if len(self.stuck_cases) < MAX_STUCK_LISTED:
            marking = dict(case.node.marking)
            self.stuck_cases.append(StuckCase(case.index, now - case.started, marking, why))

    def _critical_path(self, case: CaseState, end: float) -> list[WorkItem]:
        """The chain of tasks that determined the case's end, walked back from its last
        completion: a completion a func constraint held goes back to the task that released
        it, any other to the task whose start or completion offered it. Each task's part runs
        from its offer to where the next one's began (its wait, then its work: `_parts`), so
        the parts add up to the cycle time, less what no task accounts for (a timer, say)."""
        steps = []
        until = end
        item, by_start = case.last, False
        critical = self.critical
        while item is not None:
            if item.released_by is not None and not by_start:
                item = item.released_by  # its completion waited for this one's
                continue
            steps.append(item)
            times = critical[item.task]
            started = item.started
            if started > item.offered:
                times[0] += started - item.offered
            if until > started:
                times[1] += until - started
            until = item.offered
            by_start = item.by_start
            item = item.enabled_by
        steps.reverse()
        return steps

    def why_stuck(self, case: CaseState) -> str:
        """What an unfinished case waits for, as a person says it."""
        labels = self.net.labels
        reasons = [f"{labels[t]} runs" for t, i in case.running.items() if i not in case.finished]
        reasons += [f"{labels[i.task]} is done, held by a func constraint" for i in case.finished]
        for task, item in case.items.items():
            others = [c.index for c in item.resource.holds if c is not case]
            held = f", which holds a part for case {others[0]}" if others else ""
            reasons.append(f"{labels[task]} waits for {item.resource.key}{held}")
        reasons += [f"it waits for the message {c.name!r}" for _, c in case.node.messages]
        return f"The case cannot end: {'; '.join(reasons) or 'nothing is left to happen'}."

    def report(
        self,
        scenario: Scenario,
        *,
        span: float,
        resources: Sequence[Resource],
        started: int,
        events: int,
        assumed: tuple[str, ...],
    ) -> Prediction:
        completed = len(self.cycle_times)
        cycle_time = Spread.of([cycle for cycle, _ in self.cycle_times])
        tasks = self._task_loads(completed, cycle_time.mean if cycle_time else 0.0)
        bottleneck = max(tasks, key=lambda load: load.critical_seconds, default=None)
        typical, path = self._typical_path()
        return Prediction(
            cases=scenario.cases,
            completed=completed,
            parallel=scenario.parallel,
            seed=scenario.seed,
            cycle_time=cycle_time,
            throughput_per_hour=completed / span * 3600 if span > 0 else 0.0,
            span_seconds=span,
            actors=tuple(_load(resource, span, started) for resource in resources),
            tasks=tasks,
            bottleneck=bottleneck.task if bottleneck and bottleneck.critical_seconds else None,
            typical_case=typical,
            critical_path=path,
            stuck=tuple(self.stuck_cases),
            stuck_count=self.stuck_count,
            events=events,
            assumed=assumed,
            trace=tuple(self.trace),
        )

    def _task_loads(self, completed: int, mean_cycle: float) -> tuple[TaskLoad, ...]:
        loads = []
        per_case = 1 / completed if completed else 0.0
        for task in self.net.tasks:
            runs, duration, wait = self.tasks[task]
            if not runs:
                continue
            critical_wait, critical_work = self.critical[task]
            critical = (critical_wait + critical_work) * per_case
            loads.append(
                TaskLoad(
                    task=task,
                    label=self.net.labels[task],
                    actor=self.net.performers[task],
                    runs=int(runs),
                    mean_duration=duration / runs,
                    mean_wait=wait / runs,
                    critical_seconds=critical,
                    critical_wait_seconds=critical_wait * per_case,
                    critical_share=critical / mean_cycle if mean_cycle > 0 else 0.0,
                )
            )
        return tuple(loads)

    def _typical_path(self) -> tuple[int | None, tuple[PathStep, ...]]:
        """The typical case (the completed case nearest the median cycle time as it stood when
        that case ended) and its critical path."""
        if self.typical is None:
            return None, ()
        _, index, end, items = self.typical
        if not items:
            return index, ()  # no task completed (a cancel ended the case)
        start = items[0].case.started
        ends = [item.offered for item in items[1:]] + [end]
        return index, tuple(
            PathStep(
                task=item.task,
                label=self.net.labels[item.task],
                actor=item.resource.key,
                offered=item.offered - start,
                started=item.started - start,
                completed=item.completed - start,
                waited=item.started - item.offered,
                worked=max(until - item.started, 0.0),
            )
            for item, until in zip(items, ends, strict=True)
        )


def _load(resource: Resource, span: float, cases: int) -> ActorLoad:
    """The resource's load over the span, with its func hold still open at the end counted."""
    held = resource.held_seconds + (span - resource.held_since if resource.holds else 0.0)
    capacity = (resource.people or 1) * span
    return ActorLoad(
        actor=resource.key,
        kind=resource.kind,  # type: ignore[arg-type]
        people=resource.people,
        utilisation=resource.busy_seconds / capacity if capacity > 0 else 0.0,
        busy_seconds=resource.busy_seconds,
        held_seconds=held,
        interrupted_seconds=resource.interrupted_seconds,
        waiting_seconds=resource.waiting_seconds,
        waiting_per_case=resource.waiting_seconds / max(cases, 1),
        waited=resource.waited,
        work_items=resource.work_items,
    )
