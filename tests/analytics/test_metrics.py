"""The figures from plain rows with hand-made timestamps: no database."""

import datetime as dt

import pytest

from hrc.analytics.metrics import (
    CaseRow,
    InterruptionRow,
    ItemRow,
    JobRow,
    cobot_figures,
    covered_seconds,
    merged,
    operator_waiting,
    percentile,
    summarise,
    task_figures,
    version_figures,
)

START = dt.datetime(2025, 3, 1, 8, 0, tzinfo=dt.UTC)


def at(seconds: float) -> dt.datetime:
    return START + dt.timedelta(seconds=seconds)


def item(
    pk: int,
    task: str,
    offered: float,
    started: float | None = None,
    ended: float | None = None,
    *,
    kind: str = "operator",
    state: str = "completed",
    case: int = 1,
) -> ItemRow:
    return ItemRow(
        pk, case, task, task.upper(), "o" if kind == "operator" else "c", kind, state,
        at(offered), at(started) if started is not None else None,
        at(ended) if ended is not None else None,
    )  # fmt: skip


def job(
    pk: int,
    cobot: int,
    queued: float,
    started: float | None,
    ended: float | None,
    accepted: float | None = None,
) -> JobRow:
    """A job whose step the cobot accepted at `accepted` (by default as soon as it was leased)."""
    accepted = started if accepted is None else accepted
    return JobRow(
        pk, 1, cobot, f"cobot{cobot}", "succeeded", at(queued),
        at(started) if started is not None else None, at(ended) if ended is not None else None,
        at(accepted) if accepted is not None else None,
    )  # fmt: skip


# Percentiles -------------------------------------------------------------------------------


def test_the_median_of_an_even_count_lies_between_the_middle_two() -> None:
    assert percentile([4, 1, 3, 2], 0.5) == 2.5


@pytest.mark.parametrize(
    ("values", "q", "expected"),
    [
        (list(range(1, 11)), 0.9, 9.1),
        (list(range(1, 101)), 0.99, 99.01),
        (list(range(1, 101)), 0.5, 50.5),
        ([7.0], 0.99, 7.0),
        ([3, 9, 5], 0.0, 3),
        ([3, 9, 5], 1.0, 9),
    ],
)
def test_percentiles_interpolate_between_the_closest_ranks(
    values: list[float], q: float, expected: float
) -> None:
    assert percentile(values, q) == pytest.approx(expected)


def test_no_values_have_no_percentile_and_a_q_outside_0_to_1_is_refused() -> None:
    assert percentile([], 0.5) is None
    with pytest.raises(ValueError, match="between 0 and 1"):
        percentile([1.0], 1.5)


def test_a_summary_counts_totals_and_ranks_the_values() -> None:
    summary = summarise([30.0, 10.0, 20.0, 40.0])
    assert (summary.count, summary.total, summary.mean) == (4, 100.0, 25.0)
    assert (summary.min, summary.max) == (10.0, 40.0)
    assert summary.p50 == 25.0
    assert summary.p90 == pytest.approx(37.0)
    assert summary.p99 == pytest.approx(39.7)


def test_an_empty_summary_has_a_count_of_zero_and_no_figures() -> None:
    summary = summarise([])
    assert (summary.count, summary.total) == (0, 0.0)
    assert (summary.mean, summary.p50, summary.p99, summary.max) == (None, None, None, None)


# Intervals and utilisation -----------------------------------------------------------------


def test_overlapping_and_touching_intervals_merge_into_one() -> None:
    union = merged([(at(10), at(20)), (at(0), at(5)), (at(15), at(30)), (at(30), at(35))])
    assert union == [(at(0), at(5)), (at(10), at(35))]


def test_covered_time_counts_an_overlap_once_and_only_inside_the_window() -> None:
    intervals = [(at(-10), at(10)), (at(5), at(15)), (at(40), at(70))]
    assert covered_seconds(intervals, (at(0), at(60))) == 15 + 20


def test_a_cobots_utilisation_is_its_busy_time_over_the_window_with_overlaps_once() -> None:
    jobs = [
        job(1, cobot=1, queued=0, started=0, ended=20),
        job(2, cobot=1, queued=5, started=10, ended=30),  # overlaps the first: a lost lease
        job(3, cobot=1, queued=40, started=50, ended=60),
        job(4, cobot=1, queued=70, started=None, ended=None),  # never ran: not busy
        job(5, cobot=2, queued=0, started=25, ended=50),
    ]
    figures = {f.cobot_id: f for f in cobot_figures(jobs, (at(0), at(100)), now=at(100))}
    first, second = figures[1], figures[2]
    assert (first.jobs, first.busy_seconds, first.window_seconds) == (3, 40.0, 100.0)
    assert first.utilisation == pytest.approx(0.4)
    assert first.queue_wait.count == 3
    assert first.queue_wait.max == 10.0
    assert (second.jobs, second.busy_seconds, second.utilisation) == (1, 25.0, 0.25)
    assert second.queue_wait.p50 == 25.0


def test_a_running_job_keeps_its_cobot_busy_until_now() -> None:
    jobs = [job(1, cobot=1, queued=0, started=60, ended=None)]
    (figures,) = cobot_figures(jobs, (at(0), at(90)), now=at(90))
    assert figures.busy_seconds == 30.0
    assert figures.utilisation == pytest.approx(1 / 3)


def test_a_cobot_works_only_from_accepting_its_step_not_while_the_step_was_stuck() -> None:
    failed = JobRow(
        2,
        1,
        1,
        "cobot1",
        "failed",
        at(40),
        at(40),
        at(80),
        None,  # never accepted: stuck
    )
    jobs = [job(1, cobot=1, queued=0, started=0, ended=30, accepted=25), failed]
    (figures,) = cobot_figures(jobs, (at(0), at(100)), now=at(100))
    assert figures.busy_seconds == 5.0
    assert figures.utilisation == pytest.approx(0.05)


def test_without_a_window_a_cobot_has_no_utilisation() -> None:
    (figures,) = cobot_figures([job(1, 1, 0, 0, 10)], None, now=at(10))
    assert (figures.busy_seconds, figures.utilisation) == (0.0, None)


# Waiting and tasks -------------------------------------------------------------------------


def test_operator_waiting_is_offered_to_started_over_operator_tasks_that_started() -> None:
    items = [
        item(1, "to1", offered=0, started=12, ended=20),
        item(2, "to2", offered=20, started=50, ended=None, state="running"),
        item(3, "to3", offered=60, state="offered"),  # still waiting: not counted yet
        item(4, "tc1", offered=20, started=100, ended=110, kind="step"),  # a cobot's wait
    ]
    waiting = operator_waiting(items)
    assert (waiting.count, waiting.total, waiting.max) == (2, 42.0, 30.0)


def test_task_figures_follow_the_documents_order_and_count_only_completed_work() -> None:
    items = [
        item(1, "b", offered=0, started=10, ended=40),
        item(2, "a", offered=0, started=5, ended=10),
        item(3, "b", offered=50, started=60, ended=80),
        item(4, "b", offered=90, started=95, ended=99, state="withdrawn"),
        item(5, "z", offered=0, state="withdrawn"),
    ]
    figures = task_figures(items, order=["b", "a"])
    assert [f.task for f in figures] == ["b", "a", "z"]
    b = figures[0]
    assert (b.label, b.offered, b.completed, b.withdrawn) == ("B", 3, 2, 1)
    assert (b.work.count, b.work.min, b.work.max) == (2, 20.0, 30.0)
    assert (b.wait.count, b.wait.p50) == (3, 10.0)
    assert figures[2].work.count == 0


# A version ---------------------------------------------------------------------------------


def test_a_versions_cycle_time_counts_completed_cases_and_its_window_spans_them_all() -> None:
    cases = [
        CaseRow(1, "completed", at(0), at(100)),
        CaseRow(2, "completed", at(50), at(250)),
        CaseRow(3, "cancelled", at(60), at(70)),
        CaseRow(4, "running", at(300), None),
    ]
    interruptions = [
        InterruptionRow(
            1, 2, 10, "c", 11, "to1", "", "o", 1, "cobot1", "pause", at(60), at(90), at(61), at(89)
        ),
        InterruptionRow(
            2, 2, 12, "c", 13, "to1", "", "o", 1, "cobot1", "slow", at(95), at(100), None, None
        ),
        InterruptionRow(
            3, 4, 14, "c", 15, "to1", "", "o", 1, "cobot1", "pause", at(310), None, at(311), None
        ),
    ]
    figures = version_figures(cases, [], [], interruptions, now=at(400), recent=3)
    assert figures.cases == 4
    assert figures.by_status == {"cancelled": 1, "completed": 2, "running": 1}
    assert figures.window == (at(0), at(400))
    assert (figures.cycle.count, figures.cycle.min, figures.cycle.max) == (2, 100.0, 200.0)
    assert [c.id for c in figures.recent_cases] == [4, 3, 2]
    assert [c.cycle_seconds for c in figures.recent_cases] == [None, None, 200.0]
    assert [c.interruptions for c in figures.recent_cases] == [1, 0, 2]
    stops = figures.interruptions
    assert (stops.count, stops.ongoing) == (3, 1)
    assert stops.by_mode == {"pause": 2, "slow": 1}
    assert (stops.duration.count, stops.duration.total) == (2, 35.0)
    assert (stops.paused.count, stops.paused.total) == (1, 28.0)


def test_a_version_without_cases_has_no_window_and_empty_figures() -> None:
    figures = version_figures([], [], [], [], now=at(0))
    assert (figures.cases, figures.window, figures.cycle.count) == (0, None, 0)
    assert figures.tasks == []
    assert figures.cobots == []
