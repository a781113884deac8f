"""A case as a Gantt chart: the actors as rows, each work item a bar, each constraint arrows
between the bars of its two tasks, interruptions marked on the held task's bar.

Pure functions over hrc.analytics.metrics' rows. `build_gantt` says what is in
the chart (the API's answer); `draw_gantt` places it on a canvas for the
server-rendered SVG (templates/analytics/_gantt.html).

A bar has two parts: waiting (offered until started) and working (started
until ended, or until now while it runs). Bars of one actor that overlap in
time (two operators mapped to one actor, parallel branches) get separate lanes
of the row, so none hides another.

The time axis is broken where a stretch between two events (a long bar, a long
idle wait) lasts far longer than the case's typical one: that stretch is drawn
shortened, with a break marker saying how long it really was, so one long bar
does not squeeze every other bar to a sliver (`time_axis`).
"""

from __future__ import annotations

import datetime as dt
import itertools
import math
import statistics
from collections import defaultdict
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from typing import Final

from hrc.analytics.metrics import InterruptionRow, ItemRow, seconds

_XOf = Callable[[dt.datetime], float]


@dataclass(frozen=True)
class ActorRow:
    id: str
    type: str
    """cobot or operator."""
    who: str
    """Who performs the actor in this case: user names, a team, a cobot."""


@dataclass(frozen=True)
class ConstraintRow:
    index: int
    """Its position in the pattern document's constraints."""
    source: str
    target: str
    type: str


@dataclass(frozen=True)
class Bar:
    work_item: int
    task: str
    label: str
    actor: str
    kind: str
    state: str
    resource: str
    offered_at: dt.datetime
    started_at: dt.datetime | None
    ended_at: dt.datetime | None
    lane: int
    """0 for the row's first lane."""

    def until(self, now: dt.datetime) -> dt.datetime:
        """Where the bar ends on the chart: its end, or now while it is open."""
        return self.ended_at or now


@dataclass(frozen=True)
class GanttRow:
    actor: str
    type: str
    who: str
    lanes: int
    bars: list[Bar]


@dataclass(frozen=True)
class Arrow:
    """One constraint between two bars: from the source task's bar to the target task's.

    `from_at` is where it leaves the source bar: its end when the source ended
    before the target started, else the moment both ran (`overlapping`).
    """

    constraint: int
    type: str
    source: str
    target: str
    from_work_item: int
    to_work_item: int
    from_at: dt.datetime
    to_at: dt.datetime
    overlapping: bool


@dataclass(frozen=True)
class Mark:
    """A task held while another was in the shared area: a cobot's step paused or slowed,
    or a task kept out (a step waiting, an operator refused), marked on the held task's bar."""

    interruption: int
    work_item: int
    actor: str
    by_work_item: int
    by_task: str
    by_label: str
    by_actor: str
    cobot: str | None
    mode: str
    started_at: dt.datetime
    ended_at: dt.datetime | None
    paused_at: dt.datetime | None
    resumed_at: dt.datetime | None


@dataclass(frozen=True)
class Gantt:
    case: int
    start: dt.datetime
    end: dt.datetime
    """The case's end, or now while it runs."""
    now: dt.datetime
    open: bool
    rows: list[GanttRow]
    constraints: list[ConstraintRow]
    arrows: list[Arrow]
    marks: list[Mark]


def build_gantt(
    case: int,
    *,
    started_at: dt.datetime,
    ended_at: dt.datetime | None,
    now: dt.datetime,
    actors: Sequence[ActorRow],
    items: Iterable[ItemRow],
    constraints: Sequence[ConstraintRow],
    interruptions: Iterable[InterruptionRow],
) -> Gantt:
    """The chart of one case. Rows follow `actors` (the document's order); an item of an
    actor not among them gets a row after them."""
    by_actor: dict[str, list[ItemRow]] = defaultdict(list)
    for item in sorted(items, key=lambda i: (i.offered_at, i.id)):
        by_actor[item.actor].append(item)
    known = [actor.id for actor in actors]
    rows_of = list(actors) + [
        ActorRow(actor, "", "") for actor in sorted(by_actor) if actor not in known
    ]
    rows = [_row(actor, by_actor.get(actor.id, []), now) for actor in rows_of]
    bars = [bar for row in rows for bar in row.bars]
    end = max(ended_at or now, started_at)
    return Gantt(
        case=case,
        start=started_at,
        end=end,
        now=now,
        open=ended_at is None,
        rows=rows,
        constraints=list(constraints),
        arrows=[arrow for c in constraints for arrow in _arrows(c, bars, now)],
        marks=[_mark(i) for i in sorted(interruptions, key=lambda i: (i.started_at, i.id))],
    )


def _row(actor: ActorRow, items: list[ItemRow], now: dt.datetime) -> GanttRow:
    """The actor's bars, each in the first lane that is free when it is offered."""
    lane_ends: list[dt.datetime] = []
    bars = []
    for item in items:
        end = item.ended_at or now
        lane = next((n for n, free in enumerate(lane_ends) if free <= item.offered_at), None)
        if lane is None:
            lane = len(lane_ends)
            lane_ends.append(end)
        else:
            lane_ends[lane] = end
        label = item.label or item.task
        bar = Bar(
            item.id, item.task, label, item.actor, item.kind, item.state, item.resource,
            item.offered_at, item.started_at, item.ended_at, lane,
        )  # fmt: skip
        bars.append(bar)
    return GanttRow(actor.id, actor.type, actor.who, max(len(lane_ends), 1), bars)


def _arrows(constraint: ConstraintRow, bars: Sequence[Bar], now: dt.datetime) -> list[Arrow]:
    """An arrow to each started bar of the target task from the source task's bar that goes
    with it: one running at the same time (the nearest start), else the last one that
    ended before it started. A target bar with neither gets none."""
    sources = [b for b in bars if b.task == constraint.source and b.started_at is not None]
    arrows = []
    for target in bars:
        if target.task != constraint.target or target.started_at is None:
            continue
        begin, finish = target.started_at, target.until(now)
        overlapping = [s for s in sources if _start(s) <= finish and begin <= s.until(now)]
        if overlapping:
            source = min(overlapping, key=lambda s: (abs(seconds(_start(s), begin)), s.work_item))
            at = max(_start(source), begin)
            arrows.append(_arrow(constraint, source, target, at, at, overlapping=True))
            continue
        before = [s for s in sources if s.until(now) <= begin]
        if before:
            source = max(before, key=lambda s: (s.until(now), s.work_item))
            arrows.append(
                _arrow(constraint, source, target, source.until(now), begin, overlapping=False)
            )
    return arrows


def _start(bar: Bar) -> dt.datetime:
    assert bar.started_at is not None  # only started bars are arrow ends
    return bar.started_at


def _arrow(
    constraint: ConstraintRow,
    source: Bar,
    target: Bar,
    from_at: dt.datetime,
    to_at: dt.datetime,
    *,
    overlapping: bool,
) -> Arrow:
    return Arrow(
        constraint.index, constraint.type, constraint.source, constraint.target,
        source.work_item, target.work_item, from_at, to_at, overlapping,
    )  # fmt: skip


def _mark(row: InterruptionRow) -> Mark:
    return Mark(
        row.id, row.work_item_id, row.actor, row.by_work_item_id, row.by_task,
        row.by_label or row.by_task, row.by_actor, row.cobot, row.mode,
        row.started_at, row.ended_at, row.paused_at, row.resumed_at,
    )  # fmt: skip


# The time axis ---------------------------------------------------------------------------

# A stretch between two consecutive events longer than BREAK_RATIO times the median stretch
# (and than MIN_BREAK seconds) is drawn as if it lasted that long, with a break marker;
# but only where the median stretch would be drawn under READABLE_SHARE of the axis.
BREAK_RATIO = 4.0
MIN_BREAK = 10.0
READABLE_SHARE = 1 / 40


@dataclass(frozen=True)
class AxisPiece:
    """A stretch of the case, in seconds since it started, and where it is drawn (`shown_*`)."""

    start: float
    end: float
    shown_start: float
    shown_end: float
    broken: bool
    """Drawn shorter than it lasted: a break marker goes in its middle."""


@dataclass(frozen=True)
class TimeAxis:
    pieces: tuple[AxisPiece, ...]

    @property
    def shown_span(self) -> float:
        return self.pieces[-1].shown_end if self.pieces else 0.0

    def shown(self, offset: float) -> float:
        """Where `offset` seconds since the start is drawn, in shown seconds; clamped to the axis."""
        for piece in self.pieces:
            if offset <= piece.end:
                if offset <= piece.start:
                    return piece.shown_start
                part = (offset - piece.start) / (piece.end - piece.start)
                return piece.shown_start + part * (piece.shown_end - piece.shown_start)
        return self.shown_span

    @property
    def breaks(self) -> list[AxisPiece]:
        return [piece for piece in self.pieces if piece.broken]


def time_axis(offsets: Iterable[float], span: float) -> TimeAxis:
    """The axis over [0, span] seconds with a piece between each two consecutive event
    offsets; unbroken neighbours are merged, so a case whose typical stretch reads well on
    a linear axis has one linear piece."""
    moments = sorted({0.0, span, *(min(max(o, 0.0), span) for o in offsets)})
    gaps = [(a, b) for a, b in itertools.pairwise(moments) if b > a]
    typical = statistics.median(b - a for a, b in gaps) if gaps else span
    if typical >= READABLE_SHARE * span:
        return TimeAxis((AxisPiece(0.0, span, 0.0, span, False),))
    limit = max(BREAK_RATIO * typical, MIN_BREAK)
    pieces: list[AxisPiece] = []
    shown = 0.0
    for a, b in gaps:
        broken = b - a > limit
        length = limit if broken else b - a
        last = pieces[-1] if pieces else None
        if last is not None and not broken and not last.broken:
            pieces[-1] = AxisPiece(last.start, b, last.shown_start, shown + length, False)
        else:
            pieces.append(AxisPiece(a, b, shown, shown + length, broken))
        shown += length
    return TimeAxis(tuple(pieces))


def _event_offsets(gantt: Gantt) -> list[float]:
    moments: list[dt.datetime | None] = [gantt.now if gantt.open else None]
    for row in gantt.rows:
        for bar in row.bars:
            moments += [bar.offered_at, bar.started_at, bar.until(gantt.now)]
    for mark in gantt.marks:
        moments += [mark.started_at, mark.ended_at]
    return [seconds(gantt.start, m) for m in moments if m is not None]


# Drawing ---------------------------------------------------------------------------------

LABEL_WIDTH = 170  # the actors' names left of the chart
RIGHT_MARGIN = 24
TOP = 34  # the time axis above the rows
LANE_HEIGHT = 36
BAR_HEIGHT = 24
WAIT_HEIGHT = 8
ROW_PADDING = 6
CHAR_WIDTH = 6.6  # an estimate for 12 px system-ui, to decide whether a label fits a bar
# Tick spacings in seconds: the smallest that gives at most MAX_TICKS ticks is used.
TICK_STEPS = (1, 2, 5, 10, 15, 30, 60, 120, 300, 600, 900, 1800, 3600, 7200, 14400, 28800, 86400)
MAX_TICKS = 10


@dataclass(frozen=True)
class DrawnRow:
    row: GanttRow
    y: float
    height: float
    index: int

    @property
    def actor_y(self) -> float:
        return self.y + 20

    @property
    def who_y(self) -> float:
        return self.y + 36


@dataclass(frozen=True)
class DrawnBar:
    bar: Bar
    y: float
    wait_x: float
    wait_width: float
    x: float | None
    """The working part; None for a bar that never started."""
    width: float
    text: str
    """The label as far as it fits the working part (may be empty)."""
    seconds_waited: float | None
    seconds_worked: float | None

    @property
    def middle(self) -> float:
        return self.y + BAR_HEIGHT / 2

    @property
    def wait_y(self) -> float:
        return self.middle - WAIT_HEIGHT / 2

    @property
    def text_x(self) -> float:
        return (self.x or 0.0) + 5

    @property
    def text_y(self) -> float:
        return self.y + BAR_HEIGHT / 2 + 4


@dataclass(frozen=True)
class DrawnArrow:
    arrow: Arrow
    path: str


# What each interruption mode did to the held task, as a mark's words say it.
MARK_WORDS: Final = {"pause": "paused", "slow": "slowed", "wait": "waited", "refused": "refused"}


@dataclass(frozen=True)
class DrawnMark:
    mark: Mark
    x: float
    y: float
    width: float
    ongoing: bool

    @property
    def word(self) -> str:
        return MARK_WORDS.get(self.mark.mode, self.mark.mode)

    @property
    def title(self) -> str:
        """What held the task: the other task and its actor, in the shared area."""
        mark = self.mark
        held = f"{mark.actor} ({mark.cobot})" if mark.cobot else mark.actor
        ongoing = ", ongoing" if self.ongoing else ""
        return f"{held} {self.word}: {mark.by_label} ({mark.by_actor}) in the shared area{ongoing}"

    @property
    def icon_y(self) -> float:
        return self.y - 3


@dataclass(frozen=True)
class Tick:
    x: float
    label: str


@dataclass(frozen=True)
class DrawnBreak:
    """Where the axis leaves out time: `x` is the marker's middle, `width` the shortened stretch."""

    x: float
    width: float
    hidden: float
    """Seconds the shortened stretch really lasted."""

    @property
    def label(self) -> str:
        return format_duration(self.hidden)

    @property
    def left(self) -> float:
        return self.x - 4

    @property
    def marker(self) -> str:
        """Two slashes across the axis line, the usual sign of a broken axis."""
        y = TOP - 2
        return f"M {self.x - 7:.1f} {y:.1f} l 6 -8 M {self.x + 1:.1f} {y:.1f} l 6 -8"


@dataclass(frozen=True)
class GanttDrawing:
    gantt: Gantt
    width: float
    height: float
    left: float
    right: float
    top: float
    rows: list[DrawnRow]
    bars: list[DrawnBar]
    arrows: list[DrawnArrow]
    marks: list[DrawnMark]
    ticks: list[Tick]
    now_x: float | None
    """Where now is, while the case is open."""
    breaks: list[DrawnBreak]

    @property
    def tick_y(self) -> float:
        return self.top - 12

    @property
    def grid_top(self) -> float:
        return self.top - 6


def draw_gantt(gantt: Gantt, width: float = 1100) -> GanttDrawing:
    """The chart laid out `width` pixels wide, time running left to right."""
    right = width - RIGHT_MARGIN
    span = max(seconds(gantt.start, gantt.end), 1.0)
    axis = time_axis(_event_offsets(gantt), span)
    scale = (right - LABEL_WIDTH) / axis.shown_span

    def x_of(moment: dt.datetime) -> float:
        return LABEL_WIDTH + axis.shown(seconds(gantt.start, moment)) * scale

    rows, bars, y = [], {}, float(TOP)
    for index, row in enumerate(gantt.rows):
        height = row.lanes * LANE_HEIGHT + 2 * ROW_PADDING
        rows.append(DrawnRow(row, y, height, index))
        for bar in row.bars:
            bars[bar.work_item] = _drawn_bar(
                bar,
                y + ROW_PADDING + bar.lane * LANE_HEIGHT + (LANE_HEIGHT - BAR_HEIGHT) / 2,
                x_of,
                gantt.now,
            )
        y += height
    arrows = [
        DrawnArrow(
            a,
            _arrow_path(
                bars[a.from_work_item], bars[a.to_work_item], x_of(a.from_at), x_of(a.to_at)
            ),
        )
        for a in gantt.arrows
        if a.from_work_item in bars and a.to_work_item in bars
    ]
    marks = []
    for mark in gantt.marks:
        drawn = bars.get(mark.work_item)
        if drawn is None:
            continue
        left = x_of(mark.started_at)
        marks.append(
            DrawnMark(
                mark,
                left,
                drawn.y,
                max(x_of(mark.ended_at or gantt.now) - left, 2.0),
                mark.ended_at is None,
            )
        )
    return GanttDrawing(
        gantt=gantt,
        width=width,
        height=y + 8,
        left=LABEL_WIDTH,
        right=right,
        top=TOP,
        rows=rows,
        bars=list(bars.values()),
        arrows=arrows,
        marks=marks,
        ticks=_ticks(
            axis,
            scale,
            [LABEL_WIDTH + (p.shown_start + p.shown_end) / 2 * scale for p in axis.breaks],
        ),
        now_x=x_of(gantt.now) if gantt.open else None,
        breaks=[
            DrawnBreak(
                LABEL_WIDTH + (p.shown_start + p.shown_end) / 2 * scale,
                (p.shown_end - p.shown_start) * scale,
                p.end - p.start,
            )
            for p in axis.breaks
        ],
    )


def _drawn_bar(bar: Bar, y: float, x_of: _XOf, now: dt.datetime) -> DrawnBar:
    until = bar.until(now)
    wait_end = bar.started_at or until
    wait_x = x_of(bar.offered_at)
    wait_width = max(x_of(wait_end) - wait_x, 0.0)
    worked = seconds(bar.started_at, until) if bar.started_at else None
    if bar.started_at is None:
        return DrawnBar(
            bar, y, wait_x, wait_width, None, 0.0, "", seconds(bar.offered_at, until), None
        )
    x = x_of(bar.started_at)
    width = max(x_of(until) - x, 3.0)  # an instant's work still shows
    return DrawnBar(
        bar, y, wait_x, wait_width, x, width, _fit(bar.label, width),
        seconds(bar.offered_at, bar.started_at), worked,
    )  # fmt: skip


def _fit(text: str, width: float) -> str:
    room = int((width - 8) / CHAR_WIDTH)
    if room >= len(text):
        return text
    return text[: room - 1] + "…" if room >= 4 else ""


def _arrow_path(source: DrawnBar, target: DrawnBar, x1: float, x2: float) -> str:
    """Out of the source bar towards the target's row, into the target bar's near edge: an
    elbow when the source ended before the target began, a straight drop when both ran."""
    down = target.y > source.y
    into = target.y if down else target.y + BAR_HEIGHT
    if x2 - x1 > 2:
        return f"M {x1:.1f} {source.middle:.1f} H {x2:.1f} V {into:.1f}"
    out = source.y + BAR_HEIGHT if down else source.y
    return f"M {x1:.1f} {out:.1f} V {into:.1f}"


MIN_TICK_GAP = 48  # pixels between two tick labels


def _ticks(axis: TimeAxis, scale: float, breaks: list[float]) -> list[Tick]:
    """Ticks at round offsets inside the unbroken pieces, and one where each piece after a
    break begins, so the jump reads on the axis; none closer than MIN_TICK_GAP to the last
    or to a break's label (at `breaks`)."""
    shown = axis.shown_span
    step = next((s for s in TICK_STEPS if shown / s <= MAX_TICKS), TICK_STEPS[-1])
    ticks: list[Tick] = []
    after_break = False
    for piece in axis.pieces:
        if piece.broken:
            after_break = True
            continue
        offsets = [piece.start] if after_break else []
        first = math.ceil(piece.start / step - 1e-9)
        offsets += [n * step for n in range(first, int(piece.end // step + 1e-9) + 1)]
        after_break = False
        for offset in offsets:
            x = LABEL_WIDTH + axis.shown(offset) * scale
            if ticks and x - ticks[-1].x < MIN_TICK_GAP:
                continue
            if any(abs(x - b) < 1.5 * MIN_TICK_GAP for b in breaks):
                continue
            ticks.append(Tick(x, format_offset(offset)))
    return ticks


def format_duration(total: float) -> str:
    """A duration in words short enough for an axis: 45 s, 12 min, 1 h 05 min."""
    whole = round(total)
    if whole < 90:
        return f"{whole} s"
    minutes = round(whole / 60)
    if minutes < 60:
        return f"{minutes} min"
    return f"{minutes // 60} h {minutes % 60:02d} min"


def format_offset(total: float) -> str:
    """Seconds since the case started as m:ss, or h:mm:ss from an hour on."""
    whole = int(total)
    hours, rest = divmod(whole, 3600)
    minutes, secs = divmod(rest, 60)
    return f"{hours}:{minutes:02d}:{secs:02d}" if hours else f"{minutes}:{secs:02d}"
