"""Jobs on simulated cobots (inline: this process's threads, a real OPC UA gateway):
device calls with their outputs, interruptions for shared space, and failures that need a person."""

from __future__ import annotations

import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from hrc.cases import services
from hrc.cases.choices import CaseStatus, IncidentKind, JobState, WorkItemState
from hrc.cases.models import Case, Incident, Interruption, Job, WorkItem
from hrc.cases.simulation import Simulation
from hrc_gateway import urua
from tests.cases.patterns import scan_until_found, shared_space, unusable_outputs
from tests.support.polling import until

pytestmark = pytest.mark.django_db(transaction=True)

STEP_HANDED_OVER = urua.register_path("Inputs", urua.HANDSHAKE_BIT)


def _operator_task(case: Case, task: str) -> WorkItem:
    item: WorkItem = until(
        lambda: WorkItem.objects.filter(case=case, task=task, state=WorkItemState.OFFERED).first()
    )
    return item


def _do(simulation: Simulation, case: Case, task: str) -> WorkItem:
    item = _operator_task(case, task)
    user = simulation.users["o"]
    services.start_work_item(item, user=user)
    return item


@pytest.fixture
def simulation(request: pytest.FixtureRequest, tmp_path: Path) -> Iterator[Simulation]:
    document, time_scale = request.param
    with Simulation(document, tmp_path, time_scale=time_scale) as running:
        yield running


@pytest.mark.parametrize("simulation", [(scan_until_found(), 0.0)], indirect=True)
def test_device_calls_feed_case_data_that_later_steps_and_calls_use(simulation: Simulation) -> None:
    with simulation.running():
        [case_id] = simulation.start_cases(1)
        assert simulation.wait([case_id], timeout=60)
    case = Case.objects.get(pk=case_id)

    assert case.status == CaseStatus.COMPLETED
    assert case.data["detected"] is True
    assert len(case.data["pose"]) == 6
    assert simulation.cobot("c").read("Devices/Display/Text") == str(case.data["pose"][0])
    scans = Job.objects.filter(case=case, work_item__task="tc_scan").count()
    assert scans == 1 + sum(1 for e in case.events.filter(task="again"))


@pytest.mark.parametrize("simulation", [(shared_space(), 0.5)], indirect=True)
def test_an_operator_in_the_shared_area_pauses_the_running_cobot_until_done(
    simulation: Simulation,
) -> None:
    cobot = simulation.cobot("c")
    # The pick slowed down until the pause: on a loaded machine the operator's start and the
    # pause could otherwise come after a pick of ~1 s had ended (15 s now), and there would be
    # nothing to pause. The move under way when the pause comes stays slow to its end.
    cobot.call("Simulator/InjectFault", "slow-steps", "15")
    with simulation.running(operators=False):
        [case_id] = simulation.start_cases(1)
        case = Case.objects.get(pk=case_id)
        services.complete_work_item(_do(simulation, case, "to1"), user=simulation.users["o"])
        # The step handed over, not only leased: an operator who enters while the worker still
        # prepares the cobot holds the step back (jobs._prepare), and there is nothing to pause.
        until(lambda: cobot.read(STEP_HANDED_OVER))
        inspect = _do(simulation, case, "to2")
        until(lambda: cobot.read(urua.STATE_PROGRAM_STATE) == urua.PROGRAM_PAUSED)
        cobot.call("Simulator/ClearFault")
        time.sleep(0.3)
        assert Job.objects.get(case=case).state == JobState.RUNNING  # held, not failed
        services.complete_work_item(inspect, user=simulation.users["o"])
        until(lambda: cobot.read(urua.STATE_PROGRAM_STATE) == urua.PROGRAM_PLAYING)
        assert simulation.wait([case_id], timeout=60)

    case.refresh_from_db()
    assert case.status == CaseStatus.COMPLETED
    [interruption] = Interruption.objects.filter(case=case)
    assert interruption.paused_at
    assert interruption.resumed_at
    assert interruption.ended_at
    assert (interruption.ended_at - interruption.started_at).total_seconds() >= 0.3
    kinds = list(case.events.values_list("type", flat=True))
    assert kinds.index("task-interrupted") < kinds.index("task-resumed")
    assert simulation.executed_steps("c")[0] == 1


@pytest.mark.parametrize("simulation", [(shared_space(), 0.5)], indirect=True)
def test_a_protective_stop_is_an_incident_that_only_a_person_clears(simulation: Simulation) -> None:
    cobot = simulation.cobot("c")
    with simulation.running(operators=False):
        [case_id] = simulation.start_cases(1)
        case = Case.objects.get(pk=case_id)
        services.complete_work_item(_do(simulation, case, "to1"), user=simulation.users["o"])
        until(lambda: Job.objects.filter(case=case, state=JobState.RUNNING).exists())
        cobot.call("Simulator/InjectFault", "protective-stop", "")
        incident = until(lambda: Incident.objects.filter(case=case).first())
        assert incident.kind == IncidentKind.STEP_FAILED
        assert "PROTECTIVE_STOP" in incident.message
        assert incident.cobot_state[urua.STATE_SAFETY_MODE] == "SAFETY_MODE_PROTECTIVE_STOP"
        time.sleep(1.0)  # hrc does nothing about the stop by itself
        assert cobot.read(urua.STATE_SAFETY_MODE) == "SAFETY_MODE_PROTECTIVE_STOP"

        # The person at the cell unlocks the stop, then an engineer retries the step.
        until(lambda: _unlocked(cobot), timeout=30)
        engineer = simulation.users["o"]
        services.resolve_incident(incident, by=engineer, resolution="retry")
        services.complete_work_item(_do(simulation, case, "to2"), user=engineer)
        assert simulation.wait([case_id], timeout=60)

    case.refresh_from_db()
    assert case.status == CaseStatus.COMPLETED
    executions, tokens = simulation.executed_steps("c")
    job = Job.objects.get(case=case)
    assert executions == 1
    assert [t.split()[0] for t in tokens] == [f"{job.pk}.{job.attempt}"]


@pytest.mark.parametrize("simulation", [(shared_space(), 0.5)], indirect=True)
def test_a_stop_found_before_the_step_is_sent_keeps_the_state_as_one_found_during_it(
    simulation: Simulation,
) -> None:
    # The worker's readiness check reads the state by short names; the incident keeps it by
    # node path, as when the driver notices the stop mid-step: one shape for whoever reads it.
    cobot = simulation.cobot("c")
    cobot.call("Simulator/InjectFault", "protective-stop", "")
    with simulation.running(operators=False):
        [case_id] = simulation.start_cases(1)
        case = Case.objects.get(pk=case_id)
        services.complete_work_item(_do(simulation, case, "to1"), user=simulation.users["o"])
        incident = until(lambda: Incident.objects.filter(case=case).first())
        assert incident.cobot_state[urua.STATE_SAFETY_MODE] == "SAFETY_MODE_PROTECTIVE_STOP"
        assert "SafetyMode" not in incident.cobot_state


def _unlocked(cobot: Any) -> bool:
    try:
        cobot.call("Simulator/UnlockProtectiveStop")
    except Exception:
        return False  # too soon after the stop: a UR controller waits too
    return True


@pytest.mark.parametrize("simulation", [(unusable_outputs(), 0.0)], indirect=True)
def test_a_step_whose_outputs_do_not_map_is_an_incident_not_a_stuck_job(
    simulation: Simulation,
) -> None:
    with simulation.running(operators=False):
        [case_id] = simulation.start_cases(1)
        case = Case.objects.get(pk=case_id)
        services.complete_work_item(_do(simulation, case, "to1"), user=simulation.users["o"])
        incident = until(lambda: Incident.objects.filter(case=case).first())
        assert incident.kind == IncidentKind.CASE_FAULT
        assert "grip" in incident.message
        job = Job.objects.get(case=case)
        assert job.state == JobState.SUCCEEDED  # the step ran once and is not sent again

        # The person gives the result the step should have answered; it maps as usual.
        services.resolve_incident(
            incident, by=simulation.users["o"], resolution="skip", outputs={"grip_force": 12.5}
        )
        assert simulation.wait([case_id], timeout=30)

    case.refresh_from_db()
    assert case.status == CaseStatus.COMPLETED
    assert case.data["grip"] == 12.5
    assert simulation.executed_steps("c")[0] == 1
