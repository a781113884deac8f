"""A person's direct control of a cobot: power, brakes, programs, and reading its registers.

Engineers and admins of the cobot's organisation use it from the cobot's page
and the API (the callers check the role). Each command is confirmed, recorded
as a CobotCommand row committed before it goes out, outside any transaction
(hrc.cobots.commands; who, what, when, and what came of it), and refused while a case is using the cobot (hrc.cobots.hooks, answered
by the cases app) or while another command on it has not finished, so a
double click never sends a command twice.

The software is never the robot's safety function: no command here clears a
protective or emergency stop, and the gateway refuses to power on in one;
its message is passed on as it is. Registers are read, never written: a
register write can move the robot, which is the step handshake's job.
"""

from __future__ import annotations

import datetime as dt
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Final

from django.contrib.auth.models import User
from django.db import transaction
from django.db.models import QuerySet
from django.utils import timezone

from hrc.cobots import hooks
from hrc.cobots.choices import CommandOutcome, ControlCommand
from hrc.cobots.commands import outside_transaction
from hrc.cobots.drivers.base import (
    CobotUnreachable,
    DriverError,
    InvalidCommand,
    StepTimeout,
)
from hrc.cobots.drivers.runner import SyncDriver, driver_for_cobot
from hrc.cobots.models import Cobot, CobotCommand
from hrc.errors import Refusal
from hrc_gateway import urua

# Seconds a command may take: a UR powering on and releasing its brakes takes several.
COMMAND_TIMEOUT: Final = 30.0
# Seconds to reach the gateway before a command or a read gives up.
CONNECT_TIMEOUT: Final = 5.0
# A command unanswered for this long died with its process: it no longer holds the cobot.
STALE_AFTER: Final = dt.timedelta(seconds=COMMAND_TIMEOUT + 30)

# The URUA method each command calls (hrc_gateway/server.py).
METHODS: Final = {
    ControlCommand.POWER_ON: "PowerOn",
    ControlCommand.BRAKE_RELEASE: "BrakeRelease",
    ControlCommand.POWER_OFF: "PowerOff",
    ControlCommand.LOAD_PROGRAM: "SelectProgram",
    ControlCommand.START_PROGRAM: "StartProgram",
    ControlCommand.PAUSE_PROGRAM: "PauseProgram",
    ControlCommand.STOP_PROGRAM: "StopProgram",
}
DIRECTIONS: Final = ("Inputs", "Outputs")


class ControlError(Refusal):
    """A command or read that did not happen; `status` is the HTTP status the API answers.

    `record` is the command's row when it was recorded (None for a request
    refused before: unconfirmed, or naming no program).
    """

    code = "control-failed"

    def __init__(self, message: str, status: int, record: CobotCommand | None = None) -> None:
        super().__init__(message, status=status)
        self.record = record


@dataclass(frozen=True)
class Registers:
    """Register values by direction ("Inputs", "Outputs") and name ("Int24")."""

    inputs: dict[str, Any]
    outputs: dict[str, Any]


def run_command(
    cobot: Cobot,
    command: ControlCommand,
    *,
    by: User,
    confirmed: bool,
    program: str = "",
) -> CobotCommand:
    """Carries out one command on the cobot for `by`, an engineer or admin the caller checked.

    Returns the row, finished with outcome ok. Raises ControlError:
    400 unconfirmed, or a load that names no program (nothing recorded);
    409 the cobot is out of service, a case or another command is using it,
    or the cobot refused (a protective stop: in the gateway's words);
    400 the cobot has no such program; 503 unreachable; 504 no answer in
    time. Each of these is recorded with its outcome and message.
    """
    arguments = _arguments(cobot, command, program)
    if not confirmed:
        raise ControlError(f"{command.label} on {cobot} needs a confirmation (confirm: true).", 400)
    record = _record(cobot, command, arguments, by)
    method = METHODS[command]
    try:
        outside_transaction(
            lambda: _driver(cobot).call(method, *arguments.values(), timeout=COMMAND_TIMEOUT)
        )
    except DriverError as error:
        status, outcome = _failure(error)
        _finish(record, outcome, str(error))
        raise ControlError(str(error), status, record) from None
    except BaseException:
        # A bug, not the cobot's answer: the record must not hold the cobot until it goes stale.
        _finish(record, CommandOutcome.FAILED, "The command failed unexpectedly; see the log.")
        raise
    _finish(record, CommandOutcome.OK, "")
    return record


def _arguments(cobot: Cobot, command: ControlCommand, program: str) -> dict[str, str]:
    if command != ControlCommand.LOAD_PROGRAM:
        return {}
    try:
        return {"program": urua.program_base_name(program)}
    except ValueError:
        raise ControlError(
            f"Loading a program on {cobot} needs the program's name (program).", 400
        ) from None


def _record(
    cobot: Cobot, command: ControlCommand, arguments: dict[str, str], by: User
) -> CobotCommand:
    """The command's row: running, or refused (then raises ControlError 409 once it is saved).

    Under the cobot row lock a worker takes to lease a job, so no step starts
    between the check and the row. (A lease does not yet wait for a command
    in flight; running_commands() under the same lock is what it would ask.)
    """
    with transaction.atomic():
        locked = Cobot.objects.select_for_update(no_key=True).filter(pk=cobot.pk).first()
        reason = (
            _out_of_service(locked or cobot)
            or hooks.cobot_in_use(cobot.pk)
            or _command_in_flight(cobot)
        )
        record = CobotCommand.objects.create(
            cobot=cobot,
            command=command,
            arguments=arguments,
            requested_by=by,
            outcome=CommandOutcome.REFUSED if reason else CommandOutcome.RUNNING,
            message=reason,
            finished_at=timezone.now() if reason else None,
        )
    if reason:
        raise ControlError(reason, 409, record)
    return record


def _out_of_service(cobot: Cobot) -> str:
    if cobot.is_active:
        return ""
    return f"{cobot} is out of service (is_active is off); put it back in service first."


def _command_in_flight(cobot: Cobot) -> str:
    running = (
        running_commands()
        .filter(cobot=cobot)
        .select_related("requested_by")
        .order_by("requested_at")
        .first()
    )
    if running is None:
        return ""
    who = running.requested_by.get_username() if running.requested_by else "someone"
    return (
        f"{cobot} is still carrying out {running.get_command_display().lower()} that {who} "
        f"asked for at {timezone.localtime(running.requested_at):%H:%M:%S}; "
        "wait until it has finished."
    )


def running_commands(now: dt.datetime | None = None) -> QuerySet[CobotCommand]:
    """The commands sent and not yet answered by `now` (default: now), leaving out those lost
    with their process."""
    return CobotCommand.objects.filter(
        outcome=CommandOutcome.RUNNING, requested_at__gte=(now or timezone.now()) - STALE_AFTER
    )


def _finish(record: CobotCommand, outcome: CommandOutcome, message: str) -> None:
    record.outcome, record.message, record.finished_at = outcome, message, timezone.now()
    record.save(update_fields=["outcome", "message", "finished_at"])


def _failure(error: DriverError) -> tuple[int, CommandOutcome]:
    """The HTTP status and the outcome of a command the driver did not carry out."""
    if isinstance(error, CobotUnreachable):
        return 503, CommandOutcome.FAILED
    if isinstance(error, StepTimeout):
        return 504, CommandOutcome.FAILED
    if isinstance(error, InvalidCommand):
        return 400, CommandOutcome.REFUSED
    if type(error) is DriverError:  # not the cobot's answer: e.g. unreadable credentials
        return 502, CommandOutcome.FAILED
    return 409, CommandOutcome.REFUSED


# Reads: never refused, never recorded -------------------------------------------------------


def register_names(names: str | None) -> list[str]:
    """The register names of a `?names=Int24,Bit64` list; every register for None or "".

    Raises ControlError 400 naming every name that is not a register.
    """
    if not names:
        return urua.all_register_names()
    wanted = [name.strip() for name in names.split(",") if name.strip()]
    bad = []
    for name in wanted:
        try:
            urua.register_kind(name)
        except urua.RegisterError:
            bad.append(name)
    if bad:
        raise ControlError(
            f"Not registers: {', '.join(bad)}. Bits are Bit64–Bit127, ints Int0–Int47, "
            "doubles Double0–Double47.",
            400,
        )
    return list(dict.fromkeys(wanted))


def read_registers(cobot: Cobot, names: Sequence[str]) -> Registers:
    """The cobot's input and output registers of those names, read in one request.

    Raises ControlError (503 unreachable, 502 otherwise) when the cobot cannot answer.
    """
    paths = {
        (direction, name): urua.register_path(direction, name)
        for direction in DIRECTIONS
        for name in names
    }
    values = _read(cobot, list(paths.values()))
    by_direction: dict[str, dict[str, Any]] = {direction: {} for direction in DIRECTIONS}
    for (direction, name), path in paths.items():
        by_direction[direction][name] = values[path]
    return Registers(by_direction["Inputs"], by_direction["Outputs"])


def programs(cobot: Cobot) -> list[str]:
    """The programs the cobot can load (its gateway's Programs/Programs); ControlError if unreachable."""
    return [str(name) for name in _read(cobot, ["Programs/Programs"])["Programs/Programs"] or []]


def _read(cobot: Cobot, paths: list[str]) -> dict[str, Any]:
    try:
        return _driver(cobot).read_many(paths)
    except DriverError as error:
        raise ControlError(str(error), 503 if error.transient else 502) from None


def _driver(cobot: Cobot) -> SyncDriver:
    return driver_for_cobot(cobot, connect_timeout=CONNECT_TIMEOUT, request_timeout=CONNECT_TIMEOUT)
