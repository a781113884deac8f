"""The check's budget: a deadline that every phase walking the state space honours.

The clocks here are counters, so the tests say when time runs out without
waiting for it and without depending on the machine's speed; one test, with
room to spare, holds a generated large net to a real deadline.
"""

import itertools
import math
import time
from collections.abc import Callable

from hrc.engine import check_document, read_pattern
from hrc.engine.analysis import analyse
from hrc.engine.budget import Budget
from hrc.engine.execution import build_execution_net
from tests.engine.builders import parallel_lanes, two_lanes


def _ticking(seconds_per_read: float) -> Callable[[], float]:
    """A clock that moves on by `seconds_per_read` each time it is read."""
    ticks = itertools.count()
    return lambda: next(ticks) * seconds_per_read


def _stopping_after(reads: int) -> Callable[[], float]:
    """A clock that stands still for `reads` reads, then jumps past any deadline."""
    ticks = itertools.count()
    return lambda: 0.0 if next(ticks) < reads else math.inf


def test_the_probes_huge_pattern_is_too_large_to_decide_in_its_seconds() -> None:
    budget = Budget(seconds=2, clock=_ticking(0.001))  # 2 000 markings' worth of clock reads

    report = check_document(parallel_lanes(10, 8), budget)

    assert report.sound is None
    assert report.valid is True  # undecided is no error: the engineer may still publish
    (warning,) = report.warnings
    assert warning.code == "state-space-too-large"
    assert warning.message.startswith("The model is too large to decide in 2 s: ")
    # 2 000 markings expanded, with the successors they found: far below the marking limit.
    assert 2_000 < report.stats["markings"] < 20_000


def test_the_marking_limit_still_says_how_many_markings_were_explored() -> None:
    report = check_document(parallel_lanes(10, 8), Budget(max_markings=500))

    assert report.sound is None
    assert "too large to decide: 500 markings were explored" in report.warnings[0].message


def test_a_deadline_passing_after_the_exploration_leaves_soundness_undecided() -> None:
    net = build_execution_net(read_pattern(two_lanes([])))
    markings = analyse(net).stats["markings"]
    # One read to start the deadline, one per marking explored: the fault scan is next.
    budget = Budget(seconds=1, clock=_stopping_after(1 + markings))

    analysis = analyse(net, budget)

    assert analysis.stats["markings"] == markings  # the exploration did finish
    assert analysis.decided is False
    assert analysis.stopped_by == "time"
    assert analysis.sound is None


def test_a_fault_found_before_the_deadline_is_reported_but_no_whole_space_verdict() -> None:
    # tc2 waits for to1, and to1 for tc3, which comes after tc2: a deadlock, and tasks
    # that never start. Reads: the start, two markings explored, the fault scan; then
    # the deadline passes before the search for tasks that never start.
    data = two_lanes([("to1", "tc2", "time"), ("tc3", "to1", "time")])

    report = check_document(data, Budget(seconds=1, clock=_stopping_after(4)))

    assert report.sound is False
    assert [e.code for e in report.errors] == ["unsound"]
    assert "can get stuck" in report.errors[0].message
    assert "never start" in check_document(data).errors[-1].message  # given the time


def _counting() -> tuple[Callable[[], float], Callable[[], int]]:
    """A clock that never reaches a deadline, and how often it was read."""
    ticks = itertools.count()
    reads = [0]

    def clock() -> float:
        reads[0] = next(ticks) + 1
        return 0.0

    return clock, lambda: reads[0]


def test_every_walk_over_the_state_space_reads_the_clock_as_it_goes() -> None:
    net = build_execution_net(read_pattern(parallel_lanes(4, 8)))
    clock, reads = _counting()

    analysis = analyse(net, Budget(seconds=1, clock=clock))

    assert analysis.sound is True
    markings = analysis.stats["markings"]
    assert markings > 4 * 1024
    # The exploration reads it once per marking; the fault scan, the reversed edges and the
    # two backward searches (to the end, to a dead end) every 1 024 markings each.
    assert reads() >= 1 + markings + 4 * (markings // 1024)


def test_a_deadline_passing_in_the_backward_search_stops_it_undecided() -> None:
    net = build_execution_net(read_pattern(parallel_lanes(4, 8)))
    markings = analyse(net).stats["markings"]
    walks_before = 2 * (markings // 1024 + 1)  # the fault scan and the reversed edges
    budget = Budget(seconds=1, clock=_stopping_after(1 + markings + walks_before + 1))

    analysis = analyse(net, budget)

    assert (analysis.decided, analysis.stopped_by, analysis.faults) == (False, "time", ())


def test_a_large_generated_net_is_too_large_to_decide_within_a_small_real_budget() -> None:
    data = parallel_lanes(6, 8)  # 200 000 markings and more: seconds to explore them all

    started = time.monotonic()
    report = check_document(data, Budget(seconds=0.3))
    took = time.monotonic() - started

    assert report.sound is None
    assert report.warnings[0].message.startswith("The model is too large to decide in 0.3 s")
    # Past the deadline only the marking under way is finished and the space freed.
    assert took < 0.3 + 0.3
