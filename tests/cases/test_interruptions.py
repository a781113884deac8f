"""A space constraint's pause and resume on the cobot: claimed in a committed row, sent with no
transaction open and no lock held, recorded after, never sent twice (a fake driver stands for
the cobot)."""

from __future__ import annotations

import datetime as dt
from collections.abc import Callable
from typing import Any

import pytest
from django.contrib.auth.models import User
from django.utils import timezone

from hrc.cases import dispatch, interruptions
from hrc.cases.choices import InterruptionMode
from hrc.cases.dispatch import Task
from hrc.cases.models import Interruption
from hrc.cobots.commands import in_transaction
from hrc.cobots.drivers.base import CobotUnreachable
from hrc.cobots.models import Cobot
from hrc.organisations.models import Organisation
from tests import factories

pytestmark = pytest.mark.django_db


class FakeDriver:
    """Records each command with whether a transaction was open, then runs `meanwhile` (what
    happens elsewhere while the command is on its way) or raises `failure`."""

    def __init__(self) -> None:
        self.sent: list[tuple[str, bool]] = []
        self.meanwhile: Callable[[], None] = lambda: None
        self.failure: Exception | None = None

    def call(self, method: str, *args: Any, **options: Any) -> None:
        self.sent.append((method, in_transaction()))
        if self.failure is not None:
            raise self.failure
        self.meanwhile()


@pytest.fixture
def driver(monkeypatch: pytest.MonkeyPatch) -> FakeDriver:
    fake = FakeDriver()
    monkeypatch.setattr(interruptions, "driver_for_cobot", lambda cobot, **options: fake)
    return fake


@pytest.fixture
def rung(monkeypatch: pytest.MonkeyPatch) -> list[tuple[str, int]]:
    """The tasks sent after commit."""
    sent: list[tuple[str, int]] = []
    monkeypatch.setattr(dispatch, "send_on_commit", lambda name, pk, **kw: sent.append((name, pk)))
    return sent


@pytest.fixture
def interruption(
    organisation: Organisation, engineer: User, operator: User, cobot: Cobot
) -> Interruption:
    version = factories.make_version(organisation, published_by=engineer)
    case = factories.hand_over_case(version, started_by=engineer, operator=operator, cobot=cobot)
    item = factories.open_work_item(case, "tc1")  # leased as the cobot was free
    # Another case's step waits in the queue behind it.
    factories.hand_over_case(version, started_by=engineer, operator=operator, cobot=cobot)
    return Interruption.objects.create(
        case=case, work_item=item, by_work_item=item, cobot=cobot,
        mode=InterruptionMode.PAUSE,
    )  # fmt: skip


def _end(interruption: Interruption) -> None:
    Interruption.objects.filter(pk=interruption.pk).update(ended_at=timezone.now())


def test_the_pause_goes_out_once_with_no_transaction_open(
    driver: FakeDriver, interruption: Interruption
) -> None:
    # Another sender asks while this one's pause is on its way: the claim turns it away.
    driver.meanwhile = lambda: interruptions.interrupt_cobot(interruption.pk)

    interruptions.interrupt_cobot(interruption.pk)
    interruptions.interrupt_cobot(interruption.pk)

    assert driver.sent == [("PauseProgram", False)]
    interruption.refresh_from_db()
    assert interruption.paused_at is not None
    assert interruption.claimed_at is None


def test_a_failed_pause_is_recorded_for_the_sweeper_which_sends_it_again(
    driver: FakeDriver, interruption: Interruption
) -> None:
    driver.failure = CobotUnreachable("cobot1 does not answer")

    interruptions.interrupt_cobot(interruption.pk)

    interruption.refresh_from_db()
    assert (interruption.paused_at, interruption.claimed_at) == (None, None)
    assert interruption.error == "pause: cobot1 does not answer"
    assert interruptions.to_redo() == [(Task.INTERRUPT_COBOT, interruption.pk)]
    driver.failure = None
    interruptions.interrupt_cobot(interruption.pk)
    assert driver.sent == [("PauseProgram", False), ("PauseProgram", False)]
    assert interruptions.to_redo() == []


def test_the_resume_goes_out_once_and_rings_the_queue(
    driver: FakeDriver, interruption: Interruption, rung: list[tuple[str, int]]
) -> None:
    interruptions.interrupt_cobot(interruption.pk)
    _end(interruption)
    driver.meanwhile = lambda: interruptions.resume_cobot(interruption.pk)

    interruptions.resume_cobot(interruption.pk)
    interruptions.resume_cobot(interruption.pk)

    assert driver.sent == [("PauseProgram", False), ("StartProgram", False)]
    interruption.refresh_from_db()
    assert interruption.settled
    assert [name for name, _ in rung] == [Task.RUN_JOB]  # the cobot's queued step


def test_an_interruption_that_ends_while_its_pause_is_on_its_way_gets_its_resume(
    driver: FakeDriver, interruption: Interruption, rung: list[tuple[str, int]]
) -> None:
    def operator_done_meanwhile() -> None:
        _end(interruption)
        interruptions.resume_cobot(interruption.pk)  # turned away: the pause holds the claim

    driver.meanwhile = operator_done_meanwhile

    interruptions.interrupt_cobot(interruption.pk)

    assert driver.sent == [("PauseProgram", False)]
    assert rung == [(Task.RESUME_COBOT, interruption.pk)]
    driver.meanwhile = lambda: None
    interruptions.resume_cobot(interruption.pk)
    assert driver.sent == [("PauseProgram", False), ("StartProgram", False)]


def test_a_claim_whose_sender_died_is_taken_over(
    driver: FakeDriver, interruption: Interruption
) -> None:
    long_ago = timezone.now() - interruptions.CLAIM_EXPIRES - dt.timedelta(seconds=1)
    Interruption.objects.filter(pk=interruption.pk).update(claimed_at=timezone.now())
    interruptions.interrupt_cobot(interruption.pk)
    assert driver.sent == []  # a live claim: someone is sending it

    Interruption.objects.filter(pk=interruption.pk).update(claimed_at=long_ago)
    interruptions.interrupt_cobot(interruption.pk)

    assert driver.sent == [("PauseProgram", False)]
