"""Checks on values people type for the organisation's places."""

import re

from django.core.exceptions import ValidationError

_CELL = re.compile(r"[A-Za-z0-9_-]{0,50}")


def validate_cell(value: str) -> None:
    """A cell name is part of URLs and channel-layer group names: letters, digits, - and _ only."""
    if not _CELL.fullmatch(value):
        raise ValidationError(
            f"{value!r} is not a cell name: use up to 50 letters, digits, - and _ (no spaces)."
        )
