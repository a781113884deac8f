"""What a worker does to a cobot before a step, against a real simulated gateway."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest
from django.utils import timezone

from hrc.cases import jobs
from hrc.cobots import urua
from hrc.cobots.drivers.base import CobotNotReady
from hrc.cobots.drivers.runner import SyncDriver, driver_for
from hrc.cobots.gateway.launcher import GatewayProcess
from hrc.organisations.models import Organisation
from tests import factories
from tests.cases.patterns import PROGRAM

pytestmark = pytest.mark.django_db(transaction=True)


@pytest.fixture
def driver(tmp_path: Path) -> Iterator[SyncDriver]:
    gateway = GatewayProcess("cobot1", tmp_path / "cobot1.json", time_scale=0.0).start()
    driver = driver_for("cobot1", gateway.endpoint, step_timeout=30.0)
    driver.call("PowerOn", timeout=30)
    driver.call("SelectProgram", PROGRAM)
    driver.call("StartProgram")
    yield driver
    driver.close()
    gateway.stop()


def test_a_program_paused_by_a_cell_stop_is_not_played_again(
    driver: SyncDriver, organisation: Organisation
) -> None:
    cobot = factories.make_cobot(organisation, name="cobot1")
    driver.call("PauseProgram")  # the tablet's STOP, just after a job was leased
    cobot.stopped_at = timezone.now()
    cobot.save(update_fields=["stopped_at"])

    with pytest.raises(CobotNotReady, match="stopped from a tablet"):
        jobs._prepare(driver, cobot.pk, PROGRAM, timeout=10)
    assert driver.state()["ProgramState"] == urua.PROGRAM_PAUSED


def test_a_paused_program_of_a_running_cell_is_played_for_the_step(
    driver: SyncDriver, organisation: Organisation
) -> None:
    cobot = factories.make_cobot(organisation, name="cobot1")
    driver.call("PauseProgram")

    jobs._prepare(driver, cobot.pk, PROGRAM, timeout=10)

    assert driver.state()["ProgramState"] == urua.PROGRAM_PLAYING
