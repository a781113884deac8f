"""STOP and resume in the cobots app: rows first, robot commands after the commit, and what it
needs from cases and live asked through hrc.cobots.hooks (a fake driver stands for the cobots)."""

from __future__ import annotations

from typing import Any

import pytest
from django.contrib.auth.models import User

from hrc.cases.choices import InterruptionMode
from hrc.cases.models import Interruption
from hrc.cobots import hooks, stops
from hrc.cobots.models import CellStop, Cobot
from hrc.organisations.models import Organisation
from hrc_gateway import urua
from tests import factories

pytestmark = pytest.mark.django_db(transaction=True)


class FakeDriver:
    """A cobot that plays (or has paused) its program; it notes what the cell's rows were
    when each command reached it, as another connection sees them: committed or not."""

    def __init__(self, cobot: Cobot, program: str, sent: list[tuple[str, int, bool]]) -> None:
        self.cobot, self.program, self.sent = cobot, program, sent

    def state(self) -> dict[str, Any]:
        return {"ProgramState": self.program, "SafetyMode": "SAFETY_MODE_NORMAL"}

    def call(self, method: str, *args: Any, timeout: float = 0) -> None:
        stopped = Cobot.objects.filter(pk=self.cobot.pk, stopped_at__isnull=False).exists()
        self.sent.append((method, self.cobot.pk, stopped))


@pytest.fixture
def sent(monkeypatch: pytest.MonkeyPatch) -> list[tuple[str, int, bool]]:
    commands: list[tuple[str, int, bool]] = []

    def driver_for_cobot(cobot: Cobot, **options: Any) -> FakeDriver:
        return FakeDriver(cobot, urua.PROGRAM_PLAYING, commands)

    monkeypatch.setattr(stops, "driver_for_cobot", driver_for_cobot)
    return commands


@pytest.fixture
def told(monkeypatch: pytest.MonkeyPatch) -> list[tuple[str, Any]]:
    """What the cobots app told the apps above it, through the hooks."""
    news: list[tuple[str, Any]] = []
    registered = hooks._REGISTERED
    monkeypatch.setattr(registered, "queue_changed", lambda pk: news.append(("queue", pk)))
    monkeypatch.setattr(registered, "stop_changed", lambda stop: news.append(("stop", stop.pk)))
    monkeypatch.setattr(registered, "queue_released", lambda pk: news.append(("released", pk)))
    return news


def test_stop_holds_the_cells_cobots_then_pauses_them_after_the_commit(
    organisation: Organisation, operator: User, sent: list[Any], told: list[Any]
) -> None:
    first = factories.make_cobot(organisation, cell="A")
    second = factories.make_cobot(organisation, cell="A")
    factories.make_cobot(organisation, cell="B")

    stop = stops.stop_cell(organisation, "A", by=operator)

    assert sorted(sent) == [("PauseProgram", first.pk, True), ("PauseProgram", second.pk, True)]
    assert sorted(stop.cobots) == [first.pk, second.pk]
    assert sorted(told[:-1]) == [("queue", first.pk), ("queue", second.pk)]
    assert told[-1] == ("stop", stop.pk)  # with its problems, once they are known
    assert CellStop.objects.get().problems == {}


def test_resume_releases_the_queues_and_restarts_no_cobot_an_interruption_holds(
    organisation: Organisation,
    engineer: User,
    operator: User,
    sent: list[Any],
    told: list[Any],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    free = factories.make_cobot(organisation, cell="A")
    held = factories.make_cobot(organisation, cell="A")
    version = factories.make_version(organisation, published_by=engineer)
    case = factories.hand_over_case(version, started_by=engineer, operator=operator, cobot=held)
    item = factories.open_work_item(case, "tc1")
    Interruption.objects.create(
        case=case, work_item=item, by_work_item=item, cobot=held,
        mode=InterruptionMode.PAUSE,
    )  # fmt: skip
    stops.stop_cell(organisation, "A", by=operator)
    sent.clear()
    told.clear()
    monkeypatch.setattr(FakeDriver, "state", lambda self: {
        "ProgramState": urua.PROGRAM_PAUSED, "SafetyMode": "SAFETY_MODE_NORMAL"})  # fmt: skip

    stop = stops.resume_cell(organisation, "A", by=operator, confirmed=True)

    assert sent == [("StartProgram", free.pk, False)]  # after the commit released it
    assert sorted(told[:-1]) == sorted(
        [("queue", free.pk), ("released", free.pk), ("queue", held.pk), ("released", held.pk)]
    )
    assert told[-1] == ("stop", stop.pk)
    assert not Cobot.objects.filter(stopped_at__isnull=False).exists()


def test_resume_refuses_without_a_confirmation_or_a_stop(
    organisation: Organisation, operator: User, sent: list[Any], told: list[Any]
) -> None:
    factories.make_cobot(organisation, cell="A")

    with pytest.raises(stops.StopError) as unconfirmed:
        stops.resume_cell(organisation, "A", by=operator, confirmed=False)
    with pytest.raises(stops.StopError) as not_stopped:
        stops.resume_cell(organisation, "A", by=operator, confirmed=True)

    assert unconfirmed.value.status == 400
    assert not_stopped.value.status == 409
    assert "Cell A is not stopped." in str(not_stopped.value)
    assert sent == told == []
