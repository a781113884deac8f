"""The Gantt chart from plain rows: rows, lanes, arrows per constraint, interruption marks,
and where the drawing puts them. No database."""

import datetime as dt
import itertools

import pytest

from hrc.analytics.gantt import (
    LABEL_WIDTH,
    RIGHT_MARGIN,
    ActorRow,
    ConstraintRow,
    build_gantt,
    draw_gantt,
    format_duration,
    format_offset,
    time_axis,
)
from hrc.analytics.metrics import InterruptionRow, ItemRow

START = dt.datetime(2025, 3, 1, 8, 0, tzinfo=dt.UTC)
ACTORS = [ActorRow("c", "cobot", "ur5e-left"), ActorRow("o", "operator", "olivia")]


def at(seconds: float) -> dt.datetime:
    return START + dt.timedelta(seconds=seconds)


def item(
    pk: int,
    task: str,
    actor: str,
    offered: float,
    started: float | None,
    ended: float | None,
    state: str = "completed",
) -> ItemRow:
    return ItemRow(
        pk, 1, task, f"{task} label", actor, "operator" if actor == "o" else "step", state,
        at(offered), at(started) if started is not None else None,
        at(ended) if ended is not None else None, "olivia" if actor == "o" else "ur5e-left",
    )  # fmt: skip


def test_rows_follow_the_actors_and_hold_their_bars_in_offer_order() -> None:
    gantt = build_gantt(
        1, started_at=at(0), ended_at=at(100), now=at(120), actors=ACTORS,
        items=[item(2, "tc1", "c", 30, 40, 90), item(1, "to1", "o", 0, 10, 30),
               item(3, "x", "ghost", 0, 1, 2)],
        constraints=[], interruptions=[],
    )  # fmt: skip
    assert [(r.actor, r.type, r.who) for r in gantt.rows] == [
        ("c", "cobot", "ur5e-left"),
        ("o", "operator", "olivia"),
        ("ghost", "", ""),  # an actor the document no longer names still gets its row
    ]
    assert [b.task for b in gantt.rows[0].bars] == ["tc1"]
    assert [b.task for b in gantt.rows[1].bars] == ["to1"]
    assert (gantt.start, gantt.end, gantt.open) == (at(0), at(100), False)


def test_bars_of_one_actor_that_overlap_get_their_own_lanes() -> None:
    gantt = build_gantt(
        1, started_at=at(0), ended_at=None, now=at(120), actors=ACTORS,
        items=[item(1, "a", "o", 0, 5, 50), item(2, "b", "o", 10, 20, 60),
               item(3, "c", "o", 55, 70, None, "running")],
        constraints=[], interruptions=[],
    )  # fmt: skip
    operator = gantt.rows[1]
    assert [(b.task, b.lane) for b in operator.bars] == [("a", 0), ("b", 1), ("c", 0)]
    assert operator.lanes == 2
    assert (gantt.end, gantt.open) == (at(120), True)  # an open case runs until now


def test_a_time_constraint_draws_an_arrow_from_the_end_of_one_bar_to_the_start_of_the_next() -> (
    None
):
    time = ConstraintRow(0, "to1", "tc1", "time")
    gantt = build_gantt(
        1, started_at=at(0), ended_at=at(100), now=at(120), actors=ACTORS,
        items=[item(1, "to1", "o", 0, 10, 30), item(2, "tc1", "c", 30, 40, 90)],
        constraints=[time], interruptions=[],
    )  # fmt: skip
    (arrow,) = gantt.arrows
    assert (arrow.constraint, arrow.type, arrow.from_work_item, arrow.to_work_item) == (
        0,
        "time",
        1,
        2,
    )
    assert (arrow.from_at, arrow.to_at, arrow.overlapping) == (at(30), at(40), False)


def test_each_repetition_of_a_task_gets_its_arrow_from_the_bar_before_it() -> None:
    time = ConstraintRow(0, "to1", "tc1", "time")
    items = [
        item(1, "to1", "o", 0, 5, 10), item(2, "tc1", "c", 10, 12, 20),
        item(3, "to1", "o", 20, 25, 30), item(4, "tc1", "c", 30, 31, 40),
    ]  # fmt: skip
    gantt = build_gantt(
        1, started_at=at(0), ended_at=at(100), now=at(120), actors=ACTORS,
        items=items, constraints=[time], interruptions=[],
    )  # fmt: skip
    assert [(a.from_work_item, a.to_work_item) for a in gantt.arrows] == [(1, 2), (3, 4)]


def test_a_func_constraint_links_the_bars_while_both_run_whichever_started_first() -> None:
    # The cobot (tc1, the target) holds the part from 10 s; the operator assembles 20–40 s.
    func = ConstraintRow(1, "to1", "tc1", "func")
    gantt = build_gantt(
        1, started_at=at(0), ended_at=at(100), now=at(120), actors=ACTORS,
        items=[item(1, "to1", "o", 0, 20, 40), item(2, "tc1", "c", 0, 10, 45)],
        constraints=[func], interruptions=[],
    )  # fmt: skip
    (arrow,) = gantt.arrows
    assert (arrow.from_work_item, arrow.to_work_item, arrow.overlapping) == (1, 2, True)
    assert arrow.from_at == arrow.to_at == at(20)


def test_a_target_that_never_started_or_has_no_source_bar_gets_no_arrow() -> None:
    time = ConstraintRow(0, "to1", "tc1", "time")
    gantt = build_gantt(
        1, started_at=at(0), ended_at=None, now=at(120), actors=ACTORS,
        items=[item(1, "tc1", "c", 0, 5, 9), item(2, "to1", "o", 10, 20, 30),
               item(3, "tc1", "c", 30, None, None, "offered")],
        constraints=[time], interruptions=[],
    )  # fmt: skip
    assert gantt.arrows == []


def test_interruptions_become_marks_in_time_order() -> None:
    interruptions = [
        InterruptionRow(
            8, 1, 2, "c", 3, "to1", "", "o", 1, "ur5e-left", "slow", at(60), None, None, None
        ),
        InterruptionRow(
            7, 1, 2, "c", 3, "to1", "", "o", 1, "ur5e-left", "pause", at(50), at(55), at(50), at(55)
        ),
    ]
    gantt = build_gantt(
        1, started_at=at(0), ended_at=None, now=at(120), actors=ACTORS,
        items=[item(2, "tc1", "c", 30, 40, None, "running"), item(3, "to2", "o", 45, 50, None, "running")],
        constraints=[], interruptions=interruptions,
    )  # fmt: skip
    assert [(m.interruption, m.mode, m.work_item, m.by_work_item) for m in gantt.marks] == [
        (7, "pause", 2, 3),
        (8, "slow", 2, 3),
    ]


def test_every_kind_of_interruption_is_marked_on_the_held_tasks_bar_naming_the_other() -> None:
    actors = [*ACTORS, ActorRow("p", "operator", "paul")]
    interruptions = [
        # Paul refused while Olivia's to1 was in the area, then the cobot's step waiting for it.
        InterruptionRow(
            1,
            1,
            3,
            "p",
            1,
            "to1",
            "to1 label",
            "o",
            None,
            None,
            "refused",
            at(12),
            at(30),
            None,
            None,
        ),
        InterruptionRow(
            2,
            1,
            2,
            "c",
            1,
            "to1",
            "to1 label",
            "o",
            1,
            "ur5e-left",
            "wait",
            at(15),
            at(30),
            None,
            None,
        ),
    ]
    gantt = build_gantt(
        1, started_at=at(0), ended_at=at(60), now=at(60), actors=actors,
        items=[item(1, "to1", "o", 0, 10, 30), item(2, "tc1", "c", 15, 30, 50),
               item(3, "to2", "p", 11, 30, 40)],
        constraints=[], interruptions=interruptions,
    )  # fmt: skip

    drawing = draw_gantt(gantt, width=1024 + LABEL_WIDTH + RIGHT_MARGIN)

    bars = {b.bar.work_item: b for b in drawing.bars}
    refused, waited = drawing.marks
    assert (refused.y, waited.y) == (bars[3].y, bars[2].y)  # on the held task's row
    started = bars[2].x
    assert started is not None
    assert refused.x < waited.x < started  # from when it was kept out until it could start
    assert (refused.word, waited.word) == ("refused", "waited")
    assert refused.title == "p refused: to1 label (o) in the shared area"
    assert waited.title == "c (ur5e-left) waited: to1 label (o) in the shared area"


# Drawing -----------------------------------------------------------------------------------


def test_the_drawing_maps_time_to_x_between_the_labels_and_the_right_margin() -> None:
    interruption = InterruptionRow(
        7, 1, 2, "c", 1, "to1", "", "o", 1, "ur5e-left", "pause", at(50), at(60), None, None
    )
    gantt = build_gantt(
        1, started_at=at(0), ended_at=at(100), now=at(120), actors=ACTORS,
        items=[item(1, "to1", "o", 0, 10, 30), item(2, "tc1", "c", 30, 40, 90),
               item(3, "to9", "o", 90, None, 95, "withdrawn")],
        constraints=[ConstraintRow(0, "to1", "tc1", "time")], interruptions=[interruption],
    )  # fmt: skip
    drawing = draw_gantt(gantt, width=1024 + LABEL_WIDTH + RIGHT_MARGIN)
    scale = 1024 / 100
    bars = {b.bar.work_item: b for b in drawing.bars}
    assert bars[1].x == pytest.approx(LABEL_WIDTH + 10 * scale)
    assert bars[1].width == pytest.approx(20 * scale)
    assert (bars[1].wait_x, bars[1].wait_width) == pytest.approx((LABEL_WIDTH, 10 * scale))
    assert (bars[1].seconds_waited, bars[1].seconds_worked) == (10.0, 20.0)
    assert bars[3].x is None  # withdrawn before it started: only its wait is drawn
    assert bars[3].wait_width == pytest.approx(5 * scale)
    assert bars[2].y < bars[1].y  # the cobot's row comes first
    (arrow,) = drawing.arrows
    assert arrow.path.startswith(f"M {LABEL_WIDTH + 30 * scale:.1f} ")
    assert f"H {LABEL_WIDTH + 40 * scale:.1f}" in arrow.path
    (mark,) = drawing.marks
    assert (mark.x, mark.width) == pytest.approx((LABEL_WIDTH + 50 * scale, 10 * scale))
    assert (mark.y, mark.ongoing) == (bars[2].y, False)
    assert drawing.now_x is None  # the case has ended
    assert [t.label for t in drawing.ticks] == [format_offset(s) for s in range(0, 101, 10)]


def test_a_label_that_does_not_fit_its_bar_is_cut_short_and_an_open_case_shows_now() -> None:
    gantt = build_gantt(
        1, started_at=at(0), ended_at=None, now=at(1000), actors=ACTORS,
        items=[item(1, "a-very-long-task-name", "o", 0, 0, 200)],
        constraints=[], interruptions=[],
    )  # fmt: skip
    drawing = draw_gantt(gantt, width=600)
    (bar,) = drawing.bars
    assert bar.text.endswith("…")
    assert len(bar.text) < len(bar.bar.label)
    assert drawing.now_x == 600 - RIGHT_MARGIN


def test_offsets_read_as_minutes_and_seconds_then_hours() -> None:
    assert [format_offset(s) for s in (0, 59, 90, 3599, 3600, 7325)] == [
        "0:00",
        "0:59",
        "1:30",
        "59:59",
        "1:00:00",
        "2:02:05",
    ]


def _one_long_bar() -> list[ItemRow]:
    """Three short tasks around one that takes an hour."""
    return [
        item(1, "to1", "o", 0, 2, 8),
        item(2, "tc1", "c", 8, 10, 3610),
        item(3, "to2", "o", 3610, 3612, 3618),
        item(4, "tc2", "c", 3618, 3619, 3625),
    ]


def test_one_long_bar_no_longer_squeezes_the_short_ones_to_a_sliver() -> None:
    gantt = build_gantt(
        1, started_at=at(0), ended_at=at(3625), now=at(4000), actors=ACTORS,
        items=_one_long_bar(), constraints=[], interruptions=[],
    )  # fmt: skip
    drawing = draw_gantt(gantt, width=1100)
    bars = {b.bar.task: b for b in drawing.bars}
    linear = (1100 - RIGHT_MARGIN - LABEL_WIDTH) / 3625  # px per second without the break
    assert 6 * linear < 2  # a sliver: why the axis breaks
    assert bars["to1"].width > 60
    assert bars["to2"].width > 60
    assert bars["tc1"].width > bars["to1"].width  # the long bar stays the longest
    assert bars["tc1"].seconds_worked == 3600  # and its tooltip keeps the real time
    (broken,) = drawing.breaks
    assert broken.hidden == 3600
    assert broken.label == "1 h 00 min"
    xs = {task: bar.x for task, bar in bars.items() if bar.x is not None}
    assert xs["tc1"] < broken.x < xs["tc1"] + bars["tc1"].width
    # Time still runs left to right, and the last bar ends at the right margin.
    assert [xs[t] for t in ("to1", "tc1", "to2", "tc2")] == sorted(xs.values())
    assert xs["tc2"] + bars["tc2"].width == pytest.approx(1100 - RIGHT_MARGIN)
    # The axis reads the jump: a tick where the time after the break begins.
    assert "1:00:10" in [t.label for t in drawing.ticks]
    gaps = [b.x - a.x for a, b in itertools.pairwise(drawing.ticks)]
    assert min(gaps) >= 48


def test_an_axis_whose_typical_stretch_reads_well_is_one_linear_piece() -> None:
    # 25 s stretches among 3 s ones, but 3 s of 60 is wide enough: nothing to break.
    axis = time_axis([0, 2, 5, 6, 10, 35, 60], 60)
    (piece,) = axis.pieces
    assert (piece.start, piece.end, piece.shown_start, piece.shown_end) == (0, 60, 0, 60)
    assert axis.shown(25) == 25
    assert axis.breaks == []


def test_a_long_idle_stretch_is_shortened_to_four_typical_ones() -> None:
    axis = time_axis([0, 5, 10, 15, 1015, 1020], 1020)
    (broken,) = axis.breaks
    assert (broken.start, broken.end) == (15, 1015)
    assert broken.shown_end - broken.shown_start == 20  # 4 x the median stretch (5 s), >= 10 s
    assert axis.shown(1020) == 15 + 20 + 5
    assert axis.shown(515) == pytest.approx(15 + 10)  # halfway through, halfway along


def test_durations_read_in_seconds_minutes_then_hours() -> None:
    assert [format_duration(s) for s in (45, 300, 3600, 3900)] == [
        "45 s",
        "5 min",
        "1 h 00 min",
        "1 h 05 min",
    ]
