"""What a worker does to a cobot before a step, against a real simulated gateway."""

from __future__ import annotations

import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from django.contrib.auth.models import User
from django.utils import timezone

from hrc.cases import jobs
from hrc.cases.choices import CaseStatus, IncidentKind, JobState
from hrc.cases.models import Case, Incident, Interruption, Job
from hrc.cases.simulation import Simulation
from hrc.cobots.drivers.base import CobotNotReady, CobotPaused
from hrc.cobots.drivers.runner import SyncDriver, driver_for
from hrc.cobots.simulated import GatewayProcess
from hrc.organisations.choices import Role
from hrc.organisations.models import Organisation
from hrc_gateway import urua
from tests import factories
from tests.cases.patterns import PROGRAM, cobot_chain
from tests.support.polling import until

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


def test_a_program_paused_for_an_operator_in_a_shared_area_is_not_played_and_the_step_waits(
    driver: SyncDriver, organisation: Organisation, engineer: User, operator: User
) -> None:
    cobot = factories.make_cobot(organisation, name="cobot1")
    version = factories.make_version(organisation, published_by=engineer)
    case = factories.hand_over_case(version, started_by=engineer, operator=operator, cobot=cobot)
    job = Job.objects.get(case=case)
    # The operator entered the shared area just after the job was leased: the cobot is paused.
    Interruption.objects.create(
        case=case, work_item=job.work_item, by_work_item=factories.open_work_item(case, "tc1"),
        cobot=cobot, mode="pause", paused_at=timezone.now(),
    )  # fmt: skip
    driver.call("PauseProgram")

    with pytest.raises(CobotPaused, match="paused for an operator in a shared area") as paused:
        jobs._prepare(driver, cobot.pk, PROGRAM, timeout=10)
    assert driver.state()["ProgramState"] == urua.PROGRAM_PAUSED  # not played over the operator

    # The completion leased the job for the workers (the cobot was free then).
    assert (job.state, job.lease) == (JobState.RUNNING, 1)
    retries = job.retries_left
    jobs.fail_job(
        jobs.Lease(
            job.pk, case.pk, 1, job.attempt, job.kind, job.command, job.timeout, cobot, False
        ),
        paused.value,
    )
    job.refresh_from_db()
    assert (job.state, job.retries_left) == (JobState.QUEUED, retries)  # waits, retries spared
    assert not Incident.objects.filter(case=case).exists()
    assert jobs.lease_next_job(cobot.pk) is None  # the queue waits for the interruption


def test_a_paused_program_of_a_running_cell_is_played_for_the_step(
    driver: SyncDriver, organisation: Organisation
) -> None:
    cobot = factories.make_cobot(organisation, name="cobot1")
    driver.call("PauseProgram")

    jobs._prepare(driver, cobot.pk, PROGRAM, timeout=10)

    assert driver.state()["ProgramState"] == urua.PROGRAM_PLAYING


# From the cobot's real start state: a fresh gateway is powered off with no program loaded;
# only the person at the pendant (Simulation's power_on, where the scenario says so) acts on it.


def _chain_of(program: str, steps: int = 2) -> dict[str, Any]:
    """cobot_chain on `program` (its step 1, which every simulated program has)."""
    document = cobot_chain(steps=steps)
    document["name"] = f"Chain on {program}"
    document["actors"][0]["program"] = program
    for transition in document["processes"][0]["transitions"]:
        if "task" in transition:
            transition["task"]["step"] = {"program": program, "number": 1}
    return document


def _events(case: Case) -> list[str]:
    return list(case.events.order_by("seq").values_list("type", flat=True))


def test_a_powered_off_cobot_is_an_incident_at_once_that_names_it_and_the_remedy(
    tmp_path: Path,
) -> None:
    with Simulation(cobot_chain(steps=1), tmp_path, time_scale=0.0, power_on=False) as run:
        started = time.monotonic()
        with run.running():
            [case_id] = run.start_cases(1)
            incident = until(lambda: Incident.objects.filter(case_id=case_id).first(), 30)
        took = time.monotonic() - started
        cobot = run.cobot("c")
        assert cobot.read(urua.STATE_ROBOT_MODE) == urua.ROBOT_MODE_POWER_OFF  # never by hrc

    job = Job.objects.select_related("cobot").get(case_id=case_id)
    assert job.cobot is not None
    name = job.cobot.name
    assert took < job.timeout  # at once, not after the sweeper's lease expiries
    assert incident.kind == IncidentKind.STEP_FAILED
    assert incident.message.startswith(f"{name} is powered off: power it on at the pendant")
    assert f"/cobots/{job.cobot_id}/" in incident.message
    assert job.state == JobState.FAILED
    assert job.last_error == incident.message
    assert job.lease_expiries == 0
    events = _events(Case.objects.get(pk=case_id))
    assert events.index("step-failed") < events.index("incident-opened")


def test_a_powered_cobot_with_no_program_loaded_gets_the_steps_program(tmp_path: Path) -> None:
    with Simulation(cobot_chain(steps=2), tmp_path, time_scale=0.0) as run:
        assert run.cobot("c").read(urua.STATE_CURRENT_PROGRAM) == ""
        with run.running():
            [case_id] = run.start_cases(1)
            assert run.wait([case_id], timeout=60)
        cobot = run.cobot("c")
        assert urua.program_base_name(cobot.read(urua.STATE_CURRENT_PROGRAM)) == PROGRAM
        assert cobot.read(urua.STATE_PROGRAM_STATE) == urua.PROGRAM_PLAYING
        executions, _ = run.executed_steps("c")

    assert Case.objects.get(pk=case_id).status == CaseStatus.COMPLETED
    assert not Incident.objects.filter(case_id=case_id).exists()
    assert executions == 2


def test_a_cobot_goes_from_one_patterns_program_to_anothers(tmp_path: Path) -> None:
    other = "Cooperation_QualityInspection"
    with Simulation(_chain_of(PROGRAM), tmp_path, time_scale=0.0) as run:
        engineer = factories.make_member(run.organisation, Role.ENGINEER)
        second = factories.make_version(
            run.organisation, published_by=engineer, draft=_chain_of(other)
        )
        with run.running():
            [first_id] = run.start_cases(1)
            assert run.wait([first_id], timeout=60)
            cobot = run.cobot("c")
            assert cobot.read(urua.STATE_PROGRAM_STATE) == urua.PROGRAM_PLAYING  # left playing
            case = factories.make_case(
                second,
                started_by=engineer,
                actor_mapping={"c": run._binding("c"), "o": run._binding("o")},
            )
            assert run.wait([case.pk], timeout=60)
        assert urua.program_base_name(cobot.read(urua.STATE_CURRENT_PROGRAM)) == other

    statuses = Case.objects.filter(pk__in=[first_id, case.pk]).values_list("status", flat=True)
    assert set(statuses) == {CaseStatus.COMPLETED}
    assert not Incident.objects.filter(case_id__in=[first_id, case.pk]).exists()


def test_a_protective_stop_before_a_step_is_an_incident_and_stays(tmp_path: Path) -> None:
    with Simulation(cobot_chain(steps=1), tmp_path, time_scale=0.0) as run:
        cobot = run.cobot("c")
        cobot.call("Simulator/InjectFault", "protective-stop", "")
        with run.running():
            [case_id] = run.start_cases(1)
            incident = until(lambda: Incident.objects.filter(case_id=case_id).first(), 30)
            time.sleep(1.0)  # hrc does nothing about the stop by itself
            assert cobot.read(urua.STATE_SAFETY_MODE) == "SAFETY_MODE_PROTECTIVE_STOP"

    job = Job.objects.select_related("cobot").get(case_id=case_id)
    assert job.cobot is not None
    assert incident.message.startswith(f"{job.cobot.name} is in a protective stop")
    assert "hrc never clears it" in incident.message
    assert job.last_error == incident.message
    assert "step-failed" in _events(Case.objects.get(pk=case_id))


def test_an_unexpected_error_in_a_step_is_an_incident_at_once(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    def broken(*args: object, **kwargs: object) -> None:
        raise ValueError("'' names no program.")

    # A fault of hrc's own while preparing (issue 15 began with one like it); the rest is real.
    monkeypatch.setattr(jobs, "_prepare", broken)
    with Simulation(cobot_chain(steps=1), tmp_path, time_scale=0.0) as run, run.running():
        [case_id] = run.start_cases(1)
        incident = until(lambda: Incident.objects.filter(case_id=case_id).first(), 30)

    job = Job.objects.get(case_id=case_id)
    assert "ValueError" in incident.message
    assert "not sent again by itself" in incident.message
    assert job.state == JobState.FAILED
    assert job.last_error == incident.message
    assert _events(Case.objects.get(pk=case_id)).count("step-retry") == 0
