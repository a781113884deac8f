"""The sender thread: a worker's hold keeps the tablets' broadcasts back while it moves a cobot;
a cobot's queue is read at most once per window, and its last change is always read."""

import time
from collections.abc import Iterator
from dataclasses import dataclass

import pytest
from django.contrib.auth.models import User

from hrc.cases.models import Job
from hrc.cobots.models import Cobot
from hrc.live import groups, sender
from hrc.live.events import CobotQueueData
from hrc.organisations.models import Organisation
from tests import factories
from tests.support.polling import until

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


# Coalesced queue reads: a real sender thread reading the real queues, its reads recorded.

WINDOW = 1.0  # long beside a test's updates, so what falls inside it is certain


@dataclass
class Read:
    at: float  # time.monotonic() when the read returned
    queues: list[CobotQueueData]


@pytest.fixture
def reads(monkeypatch: pytest.MonkeyPatch) -> Iterator[tuple[sender.Sender, list[Read]]]:
    monkeypatch.setattr(sender, "QUEUE_COALESCE_SECONDS", WINDOW)
    recorded: list[Read] = []

    def read_queues(cobot_ids: list[int]) -> list[sender.Send]:
        sends = groups._queue_sends(cobot_ids)
        queues = [event["queue"] for send in sends for event in send.events]  # type: ignore[typeddict-item]
        recorded.append(Read(time.monotonic(), queues))
        return sends

    own = sender.Sender(read_queues)
    yield own, recorded
    assert own.flush(NEVER / 2)  # and its database connection is closed


def _waiting_for(cobot: Cobot, reason: str) -> float:
    """Changes the cobot's queue (what its job waits for) and says so; when it said so."""
    Job.objects.filter(cobot=cobot).update(waiting_for=reason)
    return time.monotonic()


@pytest.fixture
def queued(organisation: Organisation, engineer: User, operator: User, cobot: Cobot) -> Cobot:
    version = factories.make_version(organisation, published_by=engineer)
    for _ in range(2):  # the first one's step takes the free cobot, the second one's waits
        factories.hand_over_case(version, started_by=operator, operator=operator, cobot=cobot)
    return cobot


@pytest.mark.django_db(transaction=True)
def test_changes_inside_the_window_cost_one_read_at_its_end_that_shows_the_last(
    reads: tuple[sender.Sender, list[Read]], queued: Cobot
) -> None:
    own, recorded = reads
    own.put(sender.QueueChanged(queued.pk))
    until(lambda: recorded, timeout=10)  # the first change is read at once
    for reason in ("the first", "the second", "the last"):
        _waiting_for(queued, reason)
        own.put(sender.QueueChanged(queued.pk))

    until(lambda: len(recorded) == 2, timeout=10)
    time.sleep(WINDOW / 2)  # nothing else comes of the three changes

    first, second = recorded
    assert len(recorded) == 2
    assert second.at - first.at > WINDOW * 0.9  # at the window's end (give or take a read)
    assert [queue["waiting_for"] for queue in second.queues] == ["the last"]


@pytest.mark.django_db(transaction=True)
def test_a_change_after_the_window_is_read_at_once(
    reads: tuple[sender.Sender, list[Read]], queued: Cobot
) -> None:
    own, recorded = reads
    own.put(sender.QueueChanged(queued.pk))
    until(lambda: recorded, timeout=10)
    time.sleep(WINDOW)

    changed = _waiting_for(queued, "a reason")
    own.put(sender.QueueChanged(queued.pk))

    until(lambda: len(recorded) == 2, timeout=10)
    assert recorded[1].at - changed < WINDOW / 2
    assert [queue["waiting_for"] for queue in recorded[1].queues] == ["a reason"]


@pytest.mark.django_db(transaction=True)
def test_a_flush_reads_a_deferred_queue_at_once(
    reads: tuple[sender.Sender, list[Read]], queued: Cobot
) -> None:
    # Whoever flushes (a test, a command at exit) expects the tablets to be up to date.
    own, recorded = reads
    own.put(sender.QueueChanged(queued.pk))
    until(lambda: recorded, timeout=10)
    changed = _waiting_for(queued, "a reason")
    own.put(sender.QueueChanged(queued.pk))

    assert own.flush(10)

    assert len(recorded) == 2
    assert recorded[1].at - changed < WINDOW / 2
    assert [queue["waiting_for"] for queue in recorded[1].queues] == ["a reason"]
