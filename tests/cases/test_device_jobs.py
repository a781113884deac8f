"""Devices with queues of their own (simulated gateways, this process's threads as workers):
a device call and a cobot step of one cell run at the same time, a device's calls one at a
time, a failed call is an incident on the device's work item, and a case never starts with a
device call nobody can serve."""

from __future__ import annotations

import datetime as dt
import itertools
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from django.db.models import Q
from django.test import Client
from django.utils import timezone

from hrc.cases import device_jobs, jobs, services
from hrc.cases.choices import CaseStatus, IncidentKind, JobState
from hrc.cases.models import Case, Incident, Job
from hrc.cases.simulation import Simulation
from hrc.cobots import services as cobot_services
from hrc.cobots import stops
from hrc.cobots.models import Device
from hrc.errors import Invalid
from hrc.organisations.choices import Role
from tests.cases.patterns import PICK, PROGRAM, scan_until_found
from tests.factories import make_cobot, make_member, make_organisation, make_version
from tests.support.polling import until

AXIS = {"id": "axis", "type": "cobot", "device": "linear-axis"}


def _axis_beside_a_pick(direction: str = "right", axis_ms: int = 2000) -> dict[str, Any]:
    """The cobot picks (a 2 s tool wait) while the linear axis moves: nothing orders them."""
    tasks: list[dict[str, Any]] = [
        {"id": "split"},
        {"id": "tc_pick", "performer": "c", "label": "pick", "task": {
            "step": {"number": PICK}, "timeout": 30}},
        {"id": "ta_move", "performer": "axis", "label": "move the axis", "task": {
            "device": {"call": "linear-axis.move",
                       "args": {"direction": direction, "duration_ms": axis_ms}},
            "timeout": 30, "retries": 0}},
        {"id": "join"},
    ]  # fmt: skip
    arcs = [
        ["p0", "split"], ["split", "p1"], ["split", "p2"], ["p1", "tc_pick"], ["tc_pick", "p3"],
        ["p2", "ta_move"], ["ta_move", "p4"], ["p3", "join"], ["p4", "join"], ["join", "p5"],
    ]  # fmt: skip
    return {
        "format": "hrc-pattern/1",
        "name": "Axis beside a pick",
        "actors": [{"id": "c", "type": "cobot", "program": PROGRAM}, AXIS],
        "processes": [{
            "id": "N", "workpiece": "w", "actors": ["c", "axis"],
            "places": [{"id": f"p{i}", "tokens": int(i == 0)} for i in range(6)],
            "transitions": tasks, "arcs": arcs,
        }],
        "constraints": [],
    }  # fmt: skip


def _interval(job: Job) -> tuple[dt.datetime, dt.datetime]:
    assert job.accepted_at is not None
    assert job.ended_at is not None
    return job.accepted_at, job.ended_at


@pytest.fixture
def simulation(request: pytest.FixtureRequest, tmp_path: Path) -> Iterator[Simulation]:
    document, time_scale = request.param
    with Simulation(document, tmp_path, time_scale=time_scale) as running:
        yield running


@pytest.mark.django_db(transaction=True)
@pytest.mark.parametrize("simulation", [(_axis_beside_a_pick(axis_ms=4000), 1.0)], indirect=True)
def test_a_device_call_and_a_cobot_step_of_one_cell_run_at_the_same_time(
    simulation: Simulation,
) -> None:
    with simulation.running(operators=False):
        [case_id] = simulation.start_cases(1)
        assert simulation.wait([case_id], timeout=60)
    case = Case.objects.get(pk=case_id)
    assert case.status == CaseStatus.COMPLETED

    move = Job.objects.get(case=case, work_item__task="ta_move")
    pick = Job.objects.get(case=case, work_item__task="tc_pick")
    assert move.device is not None
    assert move.cobot_id is None
    assert move.device.kind == "linear-axis"
    assert move.work_item.device_id == move.device_id
    assert pick.cobot_id is not None
    assert pick.device_id is None
    move_from, move_to = _interval(move)
    pick_from, pick_to = _interval(pick)
    # The move takes 4 s, the pick 2 s after its program is loaded and played (up to ~2 s on
    # a loaded machine); one after the other they would not overlap at all.
    assert pick.started_at is not None
    assert pick.started_at < move_to  # the cobot took its step while the axis moved
    overlap = (min(move_to, pick_to) - max(move_from, pick_from)).total_seconds()
    assert overlap > 1.0, (move_from, move_to, pick_from, pick_to)
    assert simulation.cobot("c").read("Devices/LinearAxis/Position") == "right"


@pytest.mark.django_db(transaction=True)
@pytest.mark.parametrize("simulation", [(_axis_beside_a_pick(axis_ms=1000), 0.5)], indirect=True)
def test_a_devices_calls_run_one_at_a_time_first_come_first_served(
    simulation: Simulation,
) -> None:
    with simulation.running(operators=False):
        started = simulation.start_cases(3)
        assert simulation.wait(started, timeout=60)
    moves = list(Job.objects.filter(case_id__in=started, work_item__task="ta_move"))
    assert len({job.device_id for job in moves}) == 1
    assert all(job.state == JobState.SUCCEEDED for job in moves)
    intervals = sorted(_interval(job) for job in moves)
    for (_, ended), (began, _) in itertools.pairwise(intervals):
        assert began >= ended  # never two moves of one axis at once
    by_queue = sorted(moves, key=lambda job: (job.queued_at, job.pk))
    assert [job.pk for job in by_queue] == [
        job.pk for job in sorted(moves, key=lambda job: _interval(job)[0])
    ]


@pytest.mark.django_db(transaction=True)
@pytest.mark.parametrize(
    "simulation", [(_axis_beside_a_pick(direction="up", axis_ms=100), 0.0)], indirect=True
)
def test_a_failed_device_call_opens_an_incident_on_its_item_naming_the_device(
    simulation: Simulation,
) -> None:
    with simulation.running(operators=False):
        [case_id] = simulation.start_cases(1)
        incident = until(lambda: Incident.objects.filter(case_id=case_id).first(), timeout=30)
        # The cobot's own step is not held up by the device's failure.
        until(
            lambda: Job.objects.filter(
                case_id=case_id, work_item__task="tc_pick", state=JobState.SUCCEEDED
            ).exists(),
            timeout=30,
        )
    move = Job.objects.get(case_id=case_id, work_item__task="ta_move")
    assert move.state == JobState.FAILED
    assert incident.kind == IncidentKind.DEVICE_FAILED
    assert incident.work_item_id == move.work_item_id
    assert move.device is not None
    assert f"Device {move.device.name}" in incident.message
    assert "direction must be 'left' or 'right'" in incident.message


@pytest.mark.django_db(transaction=True)
@pytest.mark.parametrize("simulation", [(scan_until_found(), 0.0)], indirect=True)
def test_a_call_in_a_cobots_lane_runs_on_the_device_of_its_cell(simulation: Simulation) -> None:
    with simulation.running():
        [case_id] = simulation.start_cases(1)
        assert simulation.wait([case_id], timeout=60)
    calls = Job.objects.filter(case_id=case_id, work_item__task__in=["tc_scan", "tc_show"])
    assert calls.exists()
    for job in calls:
        assert job.cobot_id is None
        assert job.device is not None
        assert job.device.cell == job.device.gateway.cell == "c"


# Resolution at the start (no workers) --------------------------------------------------------


@pytest.mark.django_db
def test_a_case_start_refuses_a_call_no_device_of_the_cobots_cell_serves() -> None:
    organisation = make_organisation()
    engineer = make_member(organisation, Role.ENGINEER)
    operator = make_member(organisation, Role.OPERATOR)
    cobot = make_cobot(organisation, cell="cell-a")
    version = make_version(organisation, published_by=engineer, draft=scan_until_found())
    mapping = {"o": {"users": [operator.pk]}, "c": {"cobot": cobot.pk}}

    with pytest.raises(Invalid) as refused:
        services.start_case(version, started_by=engineer, actor_mapping=mapping)
    assert list(refused.value.fields) == ["actor_mapping.c"]
    message = str(refused.value)
    assert cobot.name in message
    assert "cell cell-a" in message
    assert "display" in message
    assert not Case.objects.exists()

    # A detector in another cell serves nobody here; one in the cell does.
    other = make_cobot(organisation, cell="cell-b")
    for kind in ("part-detection", "display"):
        cobot_services.create_device(
            organisation, name=f"{kind}-b", kind=kind, cell="cell-b", gateway=other
        )
    with pytest.raises(Invalid):
        services.start_case(version, started_by=engineer, actor_mapping=mapping)
    for kind in ("part-detection", "display"):
        cobot_services.create_device(
            organisation, name=f"{kind}-a", kind=kind, cell="cell-a", gateway=cobot
        )
    case = services.start_case(version, started_by=engineer, actor_mapping=mapping)
    devices = case.actor_mapping["c"]["devices"]
    assert set(devices) == {"part-detection", "display"}


@pytest.mark.django_db
def test_a_device_actor_maps_to_the_only_device_of_its_kind_or_must_be_named() -> None:
    organisation = make_organisation()
    engineer = make_member(organisation, Role.ENGINEER)
    cobot = make_cobot(organisation, cell="cell-a")
    version = make_version(organisation, published_by=engineer, draft=_axis_beside_a_pick())

    with pytest.raises(Invalid) as refused:
        services.start_case(version, started_by=engineer, actor_mapping={"c": {"cobot": cobot.pk}})
    assert list(refused.value.fields) == ["actor_mapping.axis"]
    assert "linear-axis" in str(refused.value)
    assert "none" in str(refused.value)

    axis = cobot_services.create_device(
        organisation, name="axis1", kind="linear-axis", cell="cell-a", gateway=cobot
    )
    case = services.start_case(
        version, started_by=engineer, actor_mapping={"c": {"cobot": cobot.pk}}
    )
    assert case.actor_mapping["axis"] == {"device": axis.pk}

    cobot_services.create_device(
        organisation, name="axis2", kind="linear-axis", cell="cell-a", gateway=cobot
    )
    with pytest.raises(Invalid) as refused:
        services.start_case(version, started_by=engineer, actor_mapping={"c": {"cobot": cobot.pk}})
    assert "several" in str(refused.value)
    mapping = {"c": {"cobot": cobot.pk}, "axis": {"device": "axis2"}}
    case = services.start_case(version, started_by=engineer, actor_mapping=mapping)
    assert case.actor_mapping["axis"]["device"] != axis.pk

    # Another organisation's axis is no one's to map.
    outsider = make_organisation()
    theirs = cobot_services.create_device(
        outsider, name="axis9", kind="linear-axis", gateway=make_cobot(outsider)
    )
    with pytest.raises(Invalid):
        services.start_case(
            version, started_by=engineer,
            actor_mapping={"c": {"cobot": cobot.pk}, "axis": {"device": theirs.pk}},
        )  # fmt: skip


def _axis_alone(axis_ms: int = 100) -> dict[str, Any]:
    """The axis moves once: a device actor's lane, no cobot's."""
    move = {
        "device": {
            "call": "linear-axis.move",
            "args": {"direction": "right", "duration_ms": axis_ms},
        },
        "timeout": 30,
    }
    return {
        "format": "hrc-pattern/1",
        "name": "Axis alone",
        "actors": [AXIS],
        "processes": [{
            "id": "N", "workpiece": "w", "actors": ["axis"],
            "places": [{"id": "p0", "tokens": 1}, {"id": "p1", "tokens": 0}],
            "transitions": [{"id": "ta_move", "performer": "axis", "label": "move", "task": move}],
            "arcs": [["p0", "ta_move"], ["ta_move", "p1"]],
        }],
        "constraints": [],
    }  # fmt: skip


@pytest.mark.django_db(transaction=True)
@pytest.mark.parametrize("simulation", [(_axis_alone(), 0.0)], indirect=True)
def test_a_stop_of_the_cell_holds_its_devices_calls_until_it_is_resumed(
    simulation: Simulation,
) -> None:
    person = make_member(simulation.organisation, Role.OPERATOR)
    device = Device.objects.get(organisation=simulation.organisation, kind="linear-axis")
    stops.stop_cell(simulation.organisation, device.cell, by=person)
    with simulation.running(operators=False):
        [case_id] = simulation.start_cases(1)
        time.sleep(1.5)  # the sweeper rings the queue every 0.5 s: nothing may start
        move = Job.objects.get(case_id=case_id)
        assert move.state == JobState.QUEUED
        assert move.sent_at is None
        assert move.waiting_for == f"cell {device.cell} to be resumed after its STOP"
        stops.resume_cell(simulation.organisation, device.cell, by=person, confirmed=True)
        assert simulation.wait([case_id], timeout=30)
    move.refresh_from_db()
    assert move.state == JobState.SUCCEEDED
    assert Case.objects.get(pk=case_id).status == CaseStatus.COMPLETED
    assert simulation.cobot("axis").read("Devices/LinearAxis/Position") == "right"


# The device's queue, leased by hand (no workers, nothing reaches a gateway) ------------------


@pytest.mark.django_db
def test_a_devices_queue_leases_one_call_at_a_time_and_never_resends_a_lost_answer() -> None:
    organisation = make_organisation()
    admin = make_member(organisation, Role.ADMIN)
    cobot = make_cobot(organisation, cell="cell-a")
    axis = cobot_services.create_device(
        organisation, name="axis1", kind="linear-axis", cell="cell-a", gateway=cobot
    )
    version = make_version(organisation, published_by=admin, draft=_axis_alone())
    first = services.start_case(version, started_by=admin)
    second = services.start_case(version, started_by=admin)
    which = Q(pk=axis.pk)

    lease = device_jobs.lease_next_device_job(which)
    assert lease is not None
    assert lease.case_id == first.pk  # first come, first served
    assert lease.cobot == cobot  # through its gateway's cobot
    assert device_jobs.lease_next_device_job(which) is None  # one call at a time
    assert Job.objects.get(case=second).state == JobState.QUEUED

    # The call went out, then the worker was lost: its lease expires, the call is queued again…
    Job.objects.filter(pk=lease.job_id).update(
        sent_at=timezone.now(), lease_expires_at=timezone.now() - dt.timedelta(seconds=1)
    )
    jobs.sweep()
    assert Job.objects.get(pk=lease.job_id).state == JobState.QUEUED
    # …and the next worker refuses to send it again: an incident on the device's item.
    device_jobs.run_next_device_job(lease.job_id)
    job = Job.objects.get(pk=lease.job_id)
    assert job.state == JobState.FAILED
    incident = Incident.objects.get(case=first)
    assert incident.kind == IncidentKind.DEVICE_FAILED
    assert incident.work_item_id == job.work_item_id
    assert "Device axis1" in incident.message
    assert "answer was lost" in incident.message

    # A person checks the axis and retries: then, and only then, the call may go out again.
    services.resolve_incident(incident, by=admin, resolution="retry")
    job.refresh_from_db()
    assert (job.state, job.sent_at) == (JobState.QUEUED, None)
    again = device_jobs.lease_next_device_job(which)
    assert again is not None
    assert again.job_id == job.pk
    assert not again.sent_before


@pytest.mark.django_db
def test_an_inactive_device_leases_nothing() -> None:
    organisation = make_organisation()
    admin = make_member(organisation, Role.ADMIN)
    cobot = make_cobot(organisation)
    axis = cobot_services.create_device(
        organisation, name="axis1", kind="linear-axis", gateway=cobot
    )
    version = make_version(organisation, published_by=admin, draft=_axis_alone())
    case = services.start_case(version, started_by=admin)
    cobot_services.update_device(axis, is_active=False)
    assert device_jobs.lease_next_device_job(Q(pk=axis.pk)) is None
    job = Job.objects.get(case=case)
    assert job.state == JobState.QUEUED
    assert job.waiting_for == "device axis1 to be put back in service"


@pytest.mark.django_db
def test_the_start_page_offers_a_device_actor_the_devices_of_its_kind() -> None:
    organisation = make_organisation()
    engineer = make_member(organisation, Role.ENGINEER)
    cobot = make_cobot(organisation, cell="cell-a")
    axis1, axis2 = (
        cobot_services.create_device(
            organisation, name=name, kind="linear-axis", cell="cell-a", gateway=cobot
        )
        for name in ("axis1", "axis2")
    )
    cobot_services.create_device(organisation, name="cam", kind="part-detection", gateway=cobot)
    version = make_version(organisation, published_by=engineer, draft=_axis_alone())
    client = Client()
    client.force_login(engineer)

    page = client.get(f"/cases/new/?version={version.pk}").content.decode()
    assert f'value="device:{axis2.pk}"' in page
    assert "cam" not in page  # another kind of device
    response = client.post(
        f"/cases/new/?version={version.pk}",
        {"actor__axis": f"device:{axis2.pk}", "reference": "", "count": "1"},
    )
    assert response.status_code == 302
    assert Case.objects.get().actor_mapping["axis"] == {"device": axis2.pk}
    assert axis1.pk != axis2.pk
