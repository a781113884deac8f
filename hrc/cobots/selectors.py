"""Reads of cobots across the organisation wall."""

from typing import Any

from django.db.models import QuerySet

from hrc.cobots.drivers.base import DriverError
from hrc.cobots.drivers.runner import driver_for_cobot
from hrc.cobots.models import Cobot, CobotCommand, CredentialsSecret, Device
from hrc.organisations.selectors import AnyUser, organisations_of


def cobots_visible_to(user: AnyUser) -> QuerySet[Cobot]:
    """The cobots of every organisation the user belongs to; none for an outsider."""
    return Cobot.objects.filter(organisation__in=organisations_of(user)).select_related(
        "organisation"
    )


def devices_visible_to(user: AnyUser) -> QuerySet[Device]:
    """The devices of every organisation the user belongs to; none for an outsider."""
    return Device.objects.filter(organisation__in=organisations_of(user)).select_related(
        "organisation", "gateway"
    )


def devices_of(organisation_id: int) -> QuerySet[Device]:
    """The organisation's devices by cell and name, with the cobots whose gateways serve them."""
    return (
        Device.objects.filter(organisation_id=organisation_id)
        .select_related("gateway")
        .order_by("cell", "name")
    )


def cobots_in_cell(organisation_id: int, cell: str) -> list[str]:
    """The names of the organisation's cobots placed in the cell."""
    return list(
        Cobot.objects.filter(organisation_id=organisation_id, cell=cell)
        .order_by("name")
        .values_list("name", flat=True)
    )


def credentials_secrets_of(organisation_id: int) -> QuerySet[CredentialsSecret]:
    """The organisation's credentials secrets by name, with who set them (never their values)."""
    return (
        CredentialsSecret.objects.filter(organisation_id=organisation_id)
        .select_related("updated_by")
        .order_by("name")
    )


def commands_of(cobot: Cobot) -> QuerySet[CobotCommand]:
    """The control commands people gave the cobot, newest first, with who gave them."""
    return CobotCommand.objects.filter(cobot=cobot).select_related("requested_by")


def live_state(cobot: Cobot, *, timeout: float = 3.0) -> dict[str, Any]:
    """What the cobot reports right now, asked through the process's driver.

    Returns {"reachable": True, "RobotMode": ..., "SafetyMode": ..., ...} or
    {"reachable": False, "error": "<what went wrong>", "transient": bool};
    never raises for a cobot that cannot be reached.
    """
    try:
        driver = driver_for_cobot(cobot, connect_timeout=timeout, request_timeout=timeout)
        return {"reachable": True, **driver.state()}
    except DriverError as error:
        return {"reachable": False, "error": str(error), "transient": error.transient}
