"""The query parameters of the analytics pages and API, read once for both.

Each reader returns None when the parameter is absent and raises BadParameter,
whose message names the parameter and what it must be, for anything else.
"""

from __future__ import annotations

import datetime as dt
import re

from django.utils import timezone
from django.utils.dateparse import parse_date, parse_datetime

from hrc.analytics.xes import LIFECYCLES, Lifecycle

ID = re.compile(r"[0-9]{1,18}")  # fits a bigint primary key


class BadParameter(ValueError):
    """A query parameter the request cannot mean; its message names it."""

    def __init__(self, name: str, message: str) -> None:
        super().__init__(message)
        self.name = name


def moment(name: str, value: str | None) -> dt.datetime | None:
    """An ISO 8601 date and time (2025-03-01T08:00:00Z) or date (2025-03-01, its midnight);
    without a zone, the server's time zone."""
    if value is None or value == "":
        return None
    try:
        parsed = parse_datetime(value)
        if parsed is None:
            day = parse_date(value)
            parsed = dt.datetime.combine(day, dt.time()) if day is not None else None
    except ValueError:  # the right shape, an impossible value (month 13)
        parsed = None
    if parsed is None:
        raise BadParameter(
            name,
            f"{name} must be a date and time in ISO 8601, such as 2025-03-01T08:00:00Z "
            f"or 2025-03-01, not {value[:40]!r}.",
        )
    return timezone.make_aware(parsed) if timezone.is_naive(parsed) else parsed


def window(
    since_value: str | None, until_value: str | None
) -> tuple[dt.datetime | None, dt.datetime | None]:
    """`since` and `until`, with until after since."""
    since, until = moment("since", since_value), moment("until", until_value)
    if since is not None and until is not None and until <= since:
        raise BadParameter("until", "until must come after since.")
    return since, until


def identifier(name: str, value: str | None) -> int | None:
    if value is None:
        return None
    if not ID.fullmatch(value):
        raise BadParameter(name, f"{name} must be an id (a whole number), not {value[:40]!r}.")
    return int(value)


def lifecycle(value: str | None) -> Lifecycle:
    if value is None or value == "pairs":
        return "pairs"
    if value == "full":
        return "full"
    allowed = " or ".join(LIFECYCLES)
    raise BadParameter("lifecycle", f"lifecycle must be {allowed}, not {value[:40]!r}.")
