"""Every write to cobots and their credentials secrets. Callers check the user's role (a
writer for cobots, an admin for secrets); these check the data (full_clean)."""

import re
from typing import Any

from django.contrib.auth.models import User
from django.core.exceptions import ValidationError
from django.db import IntegrityError, transaction

from hrc.cobots.credentials import seal
from hrc.cobots.models import Cobot, CredentialsSecret, Device
from hrc.cobots.validators import validate_secret_name
from hrc.organisations.models import Organisation
from hrc.organisations.services import ensure_cell

# The fields a caller may set; organisation is fixed once the cobot exists.
EDITABLE_FIELDS = ("name", "driver", "endpoint", "credentials_source", "cell", "is_active")


def create_cobot(organisation: Organisation, **fields: Any) -> Cobot:
    """Registers a cobot; `fields` are among EDITABLE_FIELDS and the name is free in the organisation.

    Raises django.core.exceptions.ValidationError when a value breaks the model's rules.
    """
    _reject_unknown(fields)
    cobot = Cobot(organisation=organisation, **fields)
    cobot.full_clean()
    try:
        with transaction.atomic():
            _register_cell(cobot)
            cobot.save()
    except IntegrityError:
        _raced(cobot)
    return cobot


def update_cobot(cobot: Cobot, **changes: Any) -> Cobot:
    """Changes an existing cobot's EDITABLE_FIELDS; same validation as create_cobot."""
    _reject_unknown(changes)
    for field, value in changes.items():
        setattr(cobot, field, value)
    cobot.full_clean()
    try:
        with transaction.atomic():
            _register_cell(cobot)
            cobot.save(update_fields=[*changes, "updated_at"])
    except IntegrityError:
        _raced(cobot)
    return cobot


def _raced(cobot: Cobot) -> None:
    """Another request took the name or the endpoint between full_clean and save (the unique
    constraints held): the check, run again now that theirs is committed, says which."""
    cobot.full_clean()
    raise ValidationError(
        f"Another cobot was registered with the name {cobot.name} or at {cobot.endpoint} just now."
    )


def delete_cobot(cobot: Cobot) -> None:
    """Forgets the cobot. To keep its history, set is_active=False instead."""
    cobot.delete()


def _register_cell(cobot: Cobot) -> None:
    # A cobot's cell is one of the organisation's cells, so the cell's tablet and
    # the administration's list of cells know it.
    if cobot.cell:
        ensure_cell(cobot.organisation, cobot.cell)


def _reject_unknown(fields: dict[str, Any]) -> None:
    unknown = set(fields) - set(EDITABLE_FIELDS)
    if unknown:
        raise TypeError(f"Not editable on a cobot: {', '.join(sorted(unknown))}")


# Devices -----------------------------------------------------------------------------

DEVICE_FIELDS = ("name", "kind", "cell", "gateway", "is_active")


def create_device(organisation: Organisation, **fields: Any) -> Device:
    """Registers a device of a cell; `fields` are among DEVICE_FIELDS (`gateway`: a Cobot of the
    organisation). Raises ValidationError when a value breaks the model's rules."""
    _reject_unknown_device_fields(fields)
    device = Device(organisation=organisation, **fields)
    _save_device(device, None)
    return device


def update_device(device: Device, **changes: Any) -> Device:
    """Changes a device's DEVICE_FIELDS (is_active=False deactivates it); same checks."""
    _reject_unknown_device_fields(changes)
    for field, value in changes.items():
        setattr(device, field, value)
    _save_device(device, [*changes, "updated_at"])
    return device


def _save_device(device: Device, update_fields: list[str] | None) -> None:
    device.full_clean()
    try:
        with transaction.atomic():
            if device.cell:
                ensure_cell(device.organisation, device.cell)
            device.save(update_fields=update_fields)
    except IntegrityError:
        raise ValidationError(
            {"name": f"The organisation already has a device named {device.name}."}
        ) from None


def _reject_unknown_device_fields(fields: dict[str, Any]) -> None:
    unknown = set(fields) - set(DEVICE_FIELDS)
    if unknown:
        raise TypeError(f"Not editable on a device: {', '.join(sorted(unknown))}")


# Credentials secrets -----------------------------------------------------------------

# The gateways' user names (hrc_gateway.pki): no blank and no ':'.
_USERNAME = re.compile(r"[^\s:]{1,64}")
MAX_PASSWORD = 1024


def set_credentials_secret(
    organisation: Organisation, name: str, *, username: str, password: str, by: User | None
) -> CredentialsSecret:
    """Creates the organisation's secret `name`, or replaces its user name and password.

    The caller checks that `by` is an admin of the organisation (None: the command line).
    Raises ValidationError naming the field that is wrong.
    """
    errors: dict[str, str] = {}
    try:
        validate_secret_name(name)
    except ValidationError as error:
        errors["name"] = error.messages[0]
    if not _USERNAME.fullmatch(username):
        errors["username"] = "The user name is 1 to 64 characters, with no blank and no ':'."
    if not password or len(password) > MAX_PASSWORD:
        errors["password"] = f"The password is 1 to {MAX_PASSWORD} characters."
    if errors:
        raise ValidationError(errors)
    with transaction.atomic():
        secret, _ = CredentialsSecret.objects.select_for_update().update_or_create(
            organisation=organisation,
            name=name,
            defaults={"sealed": seal(username, password), "updated_by": by},
        )
    return secret


def delete_credentials_secret(secret: CredentialsSecret) -> None:
    """Forgets the secret; refused (ValidationError) while a cobot signs in with it."""
    users = list(
        Cobot.objects.filter(
            organisation_id=secret.organisation_id, credentials_source=f"secret:{secret.name}"
        ).values_list("name", flat=True)
    )
    if users:
        raise ValidationError(
            f"The cobots {', '.join(users)} sign in with {secret.name}; give them another "
            "credentials source first."
        )
    secret.delete()
