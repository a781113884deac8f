"""A tablet's STOP of a cell, and the confirmed resume.

STOP is a convenience, not a safety function: it pauses the programs of the
cell's cobots (PauseProgram, what a space constraint's interruption sends)
and holds their queues (Cobot.stopped_at: no job is leased meanwhile), and the
queues of the cell's devices (no call starts while the cell's CellStop is active). It
never powers anything off and never touches a protective or emergency stop;
the robots' own safety systems stay in charge. Resuming needs an explicit
confirmation and restarts only the programs that are paused and that no
operator's interruption still holds.

The rows are committed first; the cobot commands follow outside the
transaction (hrc.cobots.commands), and what a cobot refused is recorded on
the CellStop and shown on the tablets (hrc.cobots.hooks: the live app tells
them, the cases app knows interruptions and starts the queues again).
"""

from __future__ import annotations

from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor

from django.contrib.auth.models import User
from django.db import IntegrityError, connections, transaction
from django.utils import timezone

from hrc.cobots import hooks
from hrc.cobots.commands import outside_transaction
from hrc.cobots.drivers.base import DriverError
from hrc.cobots.drivers.runner import driver_for_cobot
from hrc.cobots.models import CellStop, Cobot, Device
from hrc.errors import Conflict
from hrc.organisations.models import Organisation
from hrc_gateway import urua

# Seconds a cobot may take to answer PauseProgram or StartProgram.
COMMAND_TIMEOUT = 5.0


class StopError(Conflict):
    """A STOP or resume that cannot be done: 409, or 400 for a resume without its confirmation."""

    code = "stop-refused"


def stop_cell(organisation: Organisation, cell: str, *, by: User) -> CellStop:
    """Holds every active cobot of the organisation's cell and pauses its program.

    A second STOP of a stopped cell returns the first one. The caller checks
    that `by` is a member of the organisation and that `cell` is one of its
    cells; an empty cell raises ValueError.
    """
    with transaction.atomic():
        existing = _active(organisation, cell)
        if existing is not None:
            return existing
        cobots = _cell_cobots(organisation, cell)
        # A device's worker leases a call holding its device row: one that checked the cell
        # before this STOP commits has started its call before the STOP, never after.
        list(_cell_devices(organisation, cell))
        try:
            with transaction.atomic():
                stop = CellStop.objects.create(
                    organisation=organisation,
                    cell=cell,
                    stopped_by=by,
                    cobots=[c.pk for c in cobots],
                )
        except IntegrityError:  # another tablet stopped it at the same moment
            found = _active(organisation, cell)
            assert found is not None
            return found
        Cobot.objects.filter(pk__in=[c.pk for c in cobots]).update(stopped_at=timezone.now())
        for cobot in cobots:
            hooks.queue_changed(cobot.pk)
    _record_problems(stop, _command_all(cobots, _pause))
    return stop


def resume_cell(organisation: Organisation, cell: str, *, by: User, confirmed: bool) -> CellStop:
    """Ends the cell's STOP: releases the queues and restarts the programs it paused.

    Raises StopError (400) without the confirmation, (409) when the cell is not stopped.
    A cobot that a protective or emergency stop holds is left as it is, and said so.
    """
    if not confirmed:
        raise StopError("Resuming the cell needs a confirmation (confirm: true).", status=400)
    with transaction.atomic():
        stop = (
            CellStop.objects.select_for_update()
            .filter(organisation=organisation, cell=cell, resumed_at__isnull=True)
            .first()
        )
        if stop is None:
            raise StopError(f"{_name(cell)} is not stopped.")
        stop.resumed_by, stop.resumed_at = by, timezone.now()
        stop.save(update_fields=["resumed_by", "resumed_at"])
        held = list(Cobot.objects.select_for_update(no_key=True).filter(pk__in=stop.cobots))
        Cobot.objects.filter(pk__in=[c.pk for c in held]).update(stopped_at=None)
        for cobot in held:
            hooks.queue_changed(cobot.pk)
            hooks.queue_released(cobot.pk)  # the queue waited for the resume
        hooks.devices_released([device.pk for device in _cell_devices(organisation, cell)])
    _record_problems(stop, {**stop.problems, **_command_all(held, _restart)})
    return stop


def _record_problems(stop: CellStop, problems: dict[str, str]) -> None:
    with transaction.atomic():
        stop.problems = problems
        stop.save(update_fields=["problems"])
        hooks.stop_changed(stop)


def _active(organisation: Organisation, cell: str) -> CellStop | None:
    return CellStop.objects.filter(
        organisation=organisation, cell=cell, resumed_at__isnull=True
    ).first()


def _cell_cobots(organisation: Organisation, cell: str) -> list[Cobot]:
    if not cell:
        raise ValueError("A STOP names its cell; an empty one would match cobots of no cell.")
    return list(
        Cobot.objects.select_for_update(no_key=True).filter(
            organisation=organisation, cell=cell, is_active=True
        )
    )


def _cell_devices(organisation: Organisation, cell: str) -> list[Device]:
    return list(
        Device.objects.select_for_update(no_key=True).filter(organisation=organisation, cell=cell)
    )


def _command_all(cobots: list[Cobot], command: Callable[[Cobot], str]) -> dict[str, str]:
    """Runs `command` on every cobot at once; {cobot id: problem} for those that did not do it."""
    if not cobots:
        return {}

    def run(cobot: Cobot) -> str:
        try:
            return command(cobot)
        finally:
            connections.close_all()  # the pool thread's own connection, if it opened one

    def run_all() -> list[str]:
        with ThreadPoolExecutor(max_workers=min(8, len(cobots))) as pool:
            return list(pool.map(run, cobots))

    outcomes = outside_transaction(run_all)
    return {str(c.pk): problem for c, problem in zip(cobots, outcomes, strict=True) if problem}


def _pause(cobot: Cobot) -> str:
    """ "" when the cobot's program is paused (or was not playing); otherwise why not."""
    try:
        driver = driver_for_cobot(cobot, connect_timeout=COMMAND_TIMEOUT)
        state = driver.state()
        if state.get("ProgramState") != urua.PROGRAM_PLAYING:
            return ""  # nothing moves under program control; the queue is held anyway
        driver.call("PauseProgram", timeout=COMMAND_TIMEOUT)
    except DriverError as error:
        return f"not paused: {error}"
    return ""


def _restart(cobot: Cobot) -> str:
    """Restarts a paused program unless an interruption or a safety stop still holds the cobot."""
    try:
        if hooks.held_by_interruption(cobot.pk):
            return ""  # the operator in the shared area resumes it when done
        driver = driver_for_cobot(cobot, connect_timeout=COMMAND_TIMEOUT)
        state = driver.state()
        if state.get("SafetyMode") not in urua.SAFETY_MODES_THAT_MOVE:
            return f"not restarted: {state.get('SafetyMode')}; a person must clear it at the cell"
        if state.get("ProgramState") != urua.PROGRAM_PAUSED:
            return ""
        driver.call("StartProgram", timeout=COMMAND_TIMEOUT)
    except DriverError as error:
        return f"not restarted: {error}"
    return ""


def _name(cell: str) -> str:
    return f"Cell {cell}" if cell else "The floor"
