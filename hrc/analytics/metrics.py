"""What a plant engineer measures in a pattern version's cases, computed from plain rows.

Pure functions over the frozen rows below (no Django, no database), so the
numbers can be tested with hand-made timestamps: cycle times per case and per
task, operator waiting time, cobot utilisation, interruptions; each as a
Summary with percentiles. hrc.analytics.selectors reads the rows.

Durations are seconds. Something still under way (a running job, an open
interruption) lasts until `now`, the moment the rows were read.
"""

from __future__ import annotations

import datetime as dt
import math
from collections import defaultdict
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field

# The percentiles every summary carries.
PERCENTILES = (0.5, 0.9, 0.99)
OPERATOR = "operator"  # hrc.cases.choices.WorkItemKind.OPERATOR, without importing Django
COMPLETED = "completed"  # the case status and work item state of a finished one


# The rows ---------------------------------------------------------------------------------


@dataclass(frozen=True)
class CaseRow:
    id: int
    status: str
    started_at: dt.datetime
    ended_at: dt.datetime | None


@dataclass(frozen=True)
class ItemRow:
    """A work item: one offer of a task, to operators or to a cobot."""

    id: int
    case_id: int
    task: str
    label: str
    actor: str
    kind: str
    state: str
    offered_at: dt.datetime
    started_at: dt.datetime | None
    ended_at: dt.datetime | None
    resource: str = ""
    """Who did it: the operator's user name or the cobot's name; empty while nobody has."""


@dataclass(frozen=True)
class JobRow:
    id: int
    case_id: int
    cobot_id: int
    cobot: str
    state: str
    queued_at: dt.datetime
    started_at: dt.datetime | None
    ended_at: dt.datetime | None
    accepted_at: dt.datetime | None = None
    """When the cobot accepted the step that ended the job; None when it never did."""


def job_busy_interval(job: JobRow, now: dt.datetime) -> Interval | None:
    """When the job kept its cobot working: from the cobot's acceptance of the step to its end
    (a running job: from its lease until now); None for one whose step the cobot never
    accepted (stuck, refused, not ready), which kept the cobot from nothing."""
    if job.ended_at is None:
        return (job.started_at, now) if job.started_at is not None else None
    if job.accepted_at is None:
        return None
    return (job.accepted_at, job.ended_at)


@dataclass(frozen=True)
class InterruptionRow:
    """A task held (`work_item`, its `actor`) while another (`by_…`) was in the shared area."""

    id: int
    case_id: int
    work_item_id: int
    actor: str
    by_work_item_id: int
    by_task: str
    by_label: str
    by_actor: str
    cobot_id: int | None
    cobot: str | None  # None: an operator was refused
    mode: str
    started_at: dt.datetime
    ended_at: dt.datetime | None
    paused_at: dt.datetime | None
    resumed_at: dt.datetime | None


# Percentiles and summaries ----------------------------------------------------------------


def percentile(values: Sequence[float], q: float) -> float | None:
    """The q-quantile (0 ≤ q ≤ 1) by linear interpolation between the closest ranks
    (Hyndman and Fan's type 7, numpy's default); None for no values.

    `values` need not be sorted. percentile([1, 2, 3, 4], 0.5) is 2.5.
    """
    if not 0 <= q <= 1:
        raise ValueError(f"q must lie between 0 and 1, not {q}")
    if not values:
        return None
    ordered = sorted(values)
    rank = (len(ordered) - 1) * q
    below = math.floor(rank)
    above = min(below + 1, len(ordered) - 1)
    return ordered[below] + (rank - below) * (ordered[above] - ordered[below])


@dataclass(frozen=True)
class Summary:
    """count, total, mean, min, p50, p90, p99 and max of some durations (seconds);
    all but count and total are None when there are none."""

    count: int
    total: float
    mean: float | None
    min: float | None
    p50: float | None
    p90: float | None
    p99: float | None
    max: float | None


def summarise(values: Iterable[float]) -> Summary:
    ordered = sorted(values)
    if not ordered:
        return Summary(0, 0.0, None, None, None, None, None, None)
    total = math.fsum(ordered)
    p50, p90, p99 = (percentile(ordered, q) for q in PERCENTILES)
    return Summary(
        len(ordered), total, total / len(ordered), ordered[0], p50, p90, p99, ordered[-1]
    )


def seconds(start: dt.datetime, end: dt.datetime) -> float:
    return (end - start).total_seconds()


# Intervals --------------------------------------------------------------------------------

Interval = tuple[dt.datetime, dt.datetime]


def merged(intervals: Iterable[Interval]) -> list[Interval]:
    """The union of the intervals as disjoint ones in time order (touching ones join);
    empty and reversed intervals count for nothing."""
    ordered = sorted((start, end) for start, end in intervals if end > start)
    union: list[Interval] = []
    for start, end in ordered:
        if union and start <= union[-1][1]:
            union[-1] = (union[-1][0], max(union[-1][1], end))
        else:
            union.append((start, end))
    return union


def covered_seconds(intervals: Iterable[Interval], window: Interval) -> float:
    """How many seconds of `window` at least one interval covers (overlaps count once)."""
    low, high = window
    clipped = ((max(start, low), min(end, high)) for start, end in intervals)
    return math.fsum(seconds(start, end) for start, end in merged(clipped))


def observed_window(cases: Iterable[CaseRow], now: dt.datetime) -> Interval | None:
    """From the first case's start to the last one's end (now while any still runs); None
    without cases."""
    starts, ends = [], []
    for case in cases:
        starts.append(case.started_at)
        ends.append(case.ended_at or now)
    if not starts:
        return None
    return min(starts), max(max(ends), min(starts))


# Cycle times ------------------------------------------------------------------------------


def case_cycle_seconds(case: CaseRow) -> float | None:
    """Start to end of a completed case; None for one that is open, cancelled or failed
    (its duration says nothing about how long the work takes)."""
    if case.status != COMPLETED or case.ended_at is None:
        return None
    return seconds(case.started_at, case.ended_at)


def item_work_seconds(item: ItemRow) -> float | None:
    """Started to completed; None unless the item was completed (withdrawn ones are not)."""
    if item.state != COMPLETED or item.started_at is None or item.ended_at is None:
        return None
    return seconds(item.started_at, item.ended_at)


def item_wait_seconds(item: ItemRow) -> float | None:
    """Offered to started: how long the task waited for its operator or cobot; None when it
    never started."""
    if item.started_at is None:
        return None
    return seconds(item.offered_at, item.started_at)


@dataclass(frozen=True)
class TaskFigures:
    task: str
    label: str
    actor: str
    kind: str
    offered: int
    completed: int
    withdrawn: int
    work: Summary
    """Started to completed."""
    wait: Summary
    """Offered to started."""


def task_figures(items: Iterable[ItemRow], order: Sequence[str] = ()) -> list[TaskFigures]:
    """Per task: how often offered, completed and withdrawn, its work and its wait; tasks in
    `order` (the document's) first, any others after them by id."""
    by_task: dict[str, list[ItemRow]] = defaultdict(list)
    for item in items:
        by_task[item.task].append(item)
    rank = {task: index for index, task in enumerate(order)}
    figures = []
    for task in sorted(by_task, key=lambda t: (rank.get(t, len(rank)), t)):
        rows = by_task[task]
        first = rows[0]
        figures.append(
            TaskFigures(
                task=task,
                label=first.label or task,
                actor=first.actor,
                kind=first.kind,
                offered=len(rows),
                completed=sum(1 for row in rows if row.state == COMPLETED),
                withdrawn=sum(1 for row in rows if row.state == "withdrawn"),
                work=summarise(_present(item_work_seconds(row) for row in rows)),
                wait=summarise(_present(item_wait_seconds(row) for row in rows)),
            )
        )
    return figures


def operator_waiting(items: Iterable[ItemRow]) -> Summary:
    """Offered to started, over the operator tasks that started: how long work waited for a person."""
    return summarise(_present(item_wait_seconds(item) for item in items if item.kind == OPERATOR))


# Cobots -----------------------------------------------------------------------------------


@dataclass(frozen=True)
class CobotFigures:
    cobot_id: int
    cobot: str
    jobs: int
    """Jobs that ran (started), whatever their outcome."""
    busy_seconds: float
    window_seconds: float
    utilisation: float | None
    """busy / window, 0 to 1; None for an empty window."""
    queue_wait: Summary
    """Queued to started."""


def cobot_figures(
    jobs: Iterable[JobRow], window: Interval | None, now: dt.datetime
) -> list[CobotFigures]:
    """Per cobot (by name): the time its jobs kept it working within the window
    (job_busy_interval: not the time a step was stuck or retried), and their wait in its
    queue. A running job is busy until now; jobs that overlap (a lease taken over while the
    first worker still ran) count once."""
    by_cobot: dict[int, list[JobRow]] = defaultdict(list)
    for job in jobs:
        by_cobot[job.cobot_id].append(job)
    figures = []
    for cobot_id, rows in by_cobot.items():
        ran = [row for row in rows if row.started_at is not None]
        busy_intervals = [i for i in (job_busy_interval(row, now) for row in ran) if i]
        window_seconds = seconds(*window) if window else 0.0
        busy = covered_seconds(busy_intervals, window) if window else 0.0
        figures.append(
            CobotFigures(
                cobot_id=cobot_id,
                cobot=rows[0].cobot,
                jobs=len(ran),
                busy_seconds=busy,
                window_seconds=window_seconds,
                utilisation=busy / window_seconds if window_seconds > 0 else None,
                queue_wait=summarise(
                    seconds(row.queued_at, row.started_at) for row in ran if row.started_at
                ),
            )
        )
    return sorted(figures, key=lambda f: (f.cobot, f.cobot_id))


# Interruptions ----------------------------------------------------------------------------


@dataclass(frozen=True)
class InterruptionFigures:
    count: int
    ongoing: int
    by_mode: dict[str, int]
    by_cobot: dict[str, int]
    duration: Summary
    """Start to end of the interruptions that ended."""
    paused: Summary
    """Pause sent to resume sent, where both were."""


def interruption_figures(interruptions: Iterable[InterruptionRow]) -> InterruptionFigures:
    rows = list(interruptions)
    by_mode: dict[str, int] = defaultdict(int)
    by_cobot: dict[str, int] = defaultdict(int)
    for row in rows:
        by_mode[row.mode] += 1
        if row.cobot is not None:
            by_cobot[row.cobot] += 1
    return InterruptionFigures(
        count=len(rows),
        ongoing=sum(1 for row in rows if row.ended_at is None),
        by_mode=dict(sorted(by_mode.items())),
        by_cobot=dict(sorted(by_cobot.items())),
        duration=summarise(seconds(r.started_at, r.ended_at) for r in rows if r.ended_at),
        paused=summarise(
            seconds(r.paused_at, r.resumed_at) for r in rows if r.paused_at and r.resumed_at
        ),
    )


# A version's report -----------------------------------------------------------------------


@dataclass(frozen=True)
class CaseFigures:
    id: int
    status: str
    started_at: dt.datetime
    ended_at: dt.datetime | None
    cycle_seconds: float | None
    interruptions: int


@dataclass(frozen=True)
class VersionFigures:
    cases: int
    by_status: dict[str, int]
    window: Interval | None
    cycle: Summary
    """Start to end of the completed cases."""
    recent_cases: list[CaseFigures]
    tasks: list[TaskFigures]
    operator_waiting: Summary
    cobots: list[CobotFigures]
    interruptions: InterruptionFigures
    now: dt.datetime = field(compare=False)


def version_figures(
    cases: Sequence[CaseRow],
    items: Sequence[ItemRow],
    jobs: Sequence[JobRow],
    interruptions: Sequence[InterruptionRow],
    *,
    now: dt.datetime,
    task_order: Sequence[str] = (),
    recent: int = 100,
) -> VersionFigures:
    """Everything about one version's cases; `recent_cases` are the newest `recent` of them."""
    by_status: dict[str, int] = defaultdict(int)
    for case in cases:
        by_status[case.status] += 1
    window = observed_window(cases, now)
    interrupted: dict[int, int] = defaultdict(int)
    for interruption in interruptions:
        interrupted[interruption.case_id] += 1
    newest = sorted(cases, key=lambda c: (c.started_at, c.id), reverse=True)[:recent]
    return VersionFigures(
        cases=len(cases),
        by_status=dict(sorted(by_status.items())),
        window=window,
        cycle=summarise(_present(case_cycle_seconds(case) for case in cases)),
        recent_cases=[
            CaseFigures(
                c.id, c.status, c.started_at, c.ended_at, case_cycle_seconds(c), interrupted[c.id]
            )
            for c in newest
        ],
        tasks=task_figures(items, task_order),
        operator_waiting=operator_waiting(items),
        cobots=cobot_figures(jobs, window, now),
        interruptions=interruption_figures(interruptions),
        now=now,
    )


def _present(values: Iterable[float | None]) -> list[float]:
    return [value for value in values if value is not None]
