"""Every write to cobots. Callers check the user's role; these check the data (full_clean)."""

from typing import Any

from django.core.exceptions import ValidationError
from django.db import IntegrityError, transaction

from hrc.cobots.models import Cobot
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
        # Another request took the name between full_clean and save.
        raise ValidationError(
            {"name": f"{organisation} already has a cobot named {cobot.name}."}
        ) from None
    return cobot


def update_cobot(cobot: Cobot, **changes: Any) -> Cobot:
    """Changes an existing cobot's EDITABLE_FIELDS; same validation as create_cobot."""
    _reject_unknown(changes)
    for field, value in changes.items():
        setattr(cobot, field, value)
    cobot.full_clean()
    with transaction.atomic():
        _register_cell(cobot)
        cobot.save(update_fields=[*changes, "updated_at"])
    return cobot


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
