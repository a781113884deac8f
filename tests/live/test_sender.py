"""The sender thread's hold: a worker keeps the tablets' broadcasts back while it moves a cobot."""

from collections.abc import Iterator

import pytest

from hrc.live import groups, sender

# Long enough that a test passing quickly shows the release worked, not the limit.
NEVER = 60.0


@pytest.fixture
def hold_limit(monkeypatch: pytest.MonkeyPatch) -> Iterator[None]:
    monkeypatch.setattr(sender, "HOLD_LIMIT", NEVER)
    yield
    assert groups.flush(timeout=NEVER / 2), "a test left the sender held"


def test_a_hold_keeps_the_sender_back_until_released(hold_limit: None) -> None:
    hold = groups.hold()
    assert not groups.flush(timeout=0.5)
    hold.release()
    assert groups.flush(timeout=10)


def test_the_sender_waits_for_every_hold(hold_limit: None) -> None:
    first, second = groups.hold(), groups.hold()
    first.release()
    assert not groups.flush(timeout=0.5)
    second.release()
    assert groups.flush(timeout=10)


def test_releasing_twice_counts_once(hold_limit: None) -> None:
    # The driver's thread and the worker's may both release one hold.
    first = groups.hold()
    first.release()
    first.release()
    second = groups.hold()
    assert not groups.flush(timeout=0.5)
    second.release()
    assert groups.flush(timeout=10)


def test_a_hold_nobody_releases_delays_the_tablets_by_the_limit_only(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setattr(sender, "HOLD_LIMIT", 0.2)
    forgotten = groups.hold()
    try:
        assert groups.flush(timeout=10)
    finally:
        forgotten.release()
