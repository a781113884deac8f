"""A cobot as it boots, not as a fixture prepares it: what the worker does with each state.

A fresh simulated gateway is what a plant's cobot is when the shift starts:
powered off, no program loaded. No fixture here powers it on or loads a
program; where a test needs the cobot powered, the test says so and plays
the person at the pendant. Jobs run through the real job path
(`jobs.run_next_job`) against the gateway over OPC UA; the doorbells the
cases ring go to a private broker nobody consumes.
"""

from __future__ import annotations

import copy
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import pytest
from django.contrib.auth.models import User

from hrc.cases import jobs
from hrc.cases.choices import CaseStatus, EventType, JobState, WorkItemState
from hrc.cases.launcher import RedisProcess
from hrc.cases.models import Case, CaseEvent, Incident, Job
from hrc.cobots import urua
from hrc.cobots.drivers.runner import SyncDriver, driver_for
from hrc.cobots.gateway.launcher import GatewayProcess
from hrc.cobots.models import Cobot
from hrc.organisations.models import Organisation
from hrc.patterns.models import PatternVersion
from tests import factories

pytestmark = pytest.mark.django_db(transaction=True)

PICK_AND_PLACE = "Coexistence_PickAndPlace"
QUALITY_INSPECTION = "Cooperation_QualityInspection"


@dataclass
class Cell:
    """A simulated cobot as it booted, registered in the organisation."""

    cobot: Cobot
    driver: SyncDriver

    def power_on_at_the_pendant(self) -> None:
        self.driver.call("PowerOn", timeout=30)


@pytest.fixture
def cell(tmp_path: Path, organisation: Organisation, broker: RedisProcess) -> Iterator[Cell]:
    gateway = GatewayProcess("cobot1", tmp_path / "cobot1.json", time_scale=0.0).start()
    driver = driver_for("cobot1", gateway.endpoint, step_timeout=30.0)
    cobot = factories.make_cobot(organisation, name="cobot1", endpoint=gateway.endpoint)
    yield Cell(cobot, driver)
    driver.close()
    gateway.stop()


def _version(organisation: Organisation, engineer: User, program: str) -> PatternVersion:
    """The hand-over pattern whose cobot step is step 1 (home) of `program`."""
    draft = copy.deepcopy(factories.valid_document())
    draft["name"] = f"hand-over with {program}"
    draft["actors"][0]["program"] = program
    return factories.make_version(organisation, published_by=engineer, draft=draft)


def _step_of(version: PatternVersion, cell: Cell, engineer: User, operator: User) -> Job:
    """A case whose operator has done their part: its cobot step is queued; run it once."""
    case = factories.hand_over_case(
        version, started_by=engineer, operator=operator, cobot=cell.cobot
    )
    job = Job.objects.get(case=case)
    jobs.run_next_job(job.pk)
    job.refresh_from_db()
    return job


def test_a_powered_off_cobot_is_an_incident_at_once_that_names_it_and_what_to_do(
    cell: Cell, organisation: Organisation, engineer: User, operator: User
) -> None:
    assert cell.driver.state()["RobotMode"] == urua.ROBOT_MODE_POWER_OFF
    version = _version(organisation, engineer, PICK_AND_PLACE)
    started = time.monotonic()

    job = _step_of(version, cell, engineer, operator)

    took = time.monotonic() - started
    expected = (
        f"cobot1 is powered off: power it on at the pendant or from its page "
        f"(/cobots/{cell.cobot.pk}/)."
    )
    assert job.state == JobState.FAILED
    assert job.last_error == expected
    incident = Incident.objects.get(case=job.case_id)
    assert incident.message == expected
    assert CaseEvent.objects.filter(case=job.case_id, type=EventType.INCIDENT_OPENED).exists()
    assert took < job.timeout  # at once, not after the sweeper's lease expiries
    # hrc did not power it on by itself.
    assert cell.driver.state()["RobotMode"] == urua.ROBOT_MODE_POWER_OFF


def test_with_no_program_loaded_the_steps_program_is_loaded_and_played(
    cell: Cell, organisation: Organisation, engineer: User, operator: User
) -> None:
    cell.power_on_at_the_pendant()
    assert cell.driver.state()["CurrentProgram"] == ""
    version = _version(organisation, engineer, PICK_AND_PLACE)

    job = _step_of(version, cell, engineer, operator)

    assert job.state == JobState.SUCCEEDED, job.last_error
    assert Case.objects.get(pk=job.case_id).status == CaseStatus.COMPLETED
    state = cell.driver.state()
    assert urua.program_base_name(state["CurrentProgram"]) == PICK_AND_PLACE
    assert state["ProgramState"] == urua.PROGRAM_PLAYING


def test_a_cobot_goes_from_one_patterns_program_to_anothers(
    cell: Cell, organisation: Organisation, engineer: User, operator: User
) -> None:
    cell.power_on_at_the_pendant()
    first = _step_of(_version(organisation, engineer, PICK_AND_PLACE), cell, engineer, operator)
    assert first.state == JobState.SUCCEEDED, first.last_error
    assert cell.driver.state()["ProgramState"] == urua.PROGRAM_PLAYING  # left playing

    second = _step_of(
        _version(organisation, engineer, QUALITY_INSPECTION), cell, engineer, operator
    )

    assert second.state == JobState.SUCCEEDED, second.last_error
    assert Case.objects.get(pk=second.case_id).status == CaseStatus.COMPLETED
    assert not Incident.objects.exists()
    state = cell.driver.state()
    assert urua.program_base_name(state["CurrentProgram"]) == QUALITY_INSPECTION
    assert state["ProgramState"] == urua.PROGRAM_PLAYING


def test_a_protective_stop_is_an_incident_and_stays_until_a_person_clears_it(
    cell: Cell, organisation: Organisation, engineer: User, operator: User
) -> None:
    cell.power_on_at_the_pendant()
    cell.driver.call("Simulator/InjectFault", "protective-stop", "", timeout=10)
    version = _version(organisation, engineer, PICK_AND_PLACE)

    job = _step_of(version, cell, engineer, operator)

    assert job.state == JobState.FAILED
    assert "cobot1 is in a protective stop" in job.last_error
    assert "hrc never clears it" in job.last_error
    assert Incident.objects.get(case=job.case_id).message == job.last_error
    assert job.work_item.state == WorkItemState.RUNNING  # the task waits for the person
    time.sleep(0.5)  # nothing clears it afterwards either
    assert cell.driver.state()["SafetyMode"] == "SAFETY_MODE_PROTECTIVE_STOP"
