"""The query parameters of the analytics pages and API, read once for both.

Each reader returns None when the parameter is absent and raises BadParameter,
whose message names the parameter and what it must be, for anything else; the
API and the pages answer it as they answer every refusal (hrc.errors).
"""

from __future__ import annotations

import datetime as dt
import re

from django.utils import timezone
from django.utils.dateparse import parse_date, parse_datetime

from hrc.analytics.xes import LIFECYCLES, Lifecycle
from hrc.errors import Invalid

ID = re.compile(r"[0-9]{1,18}")  # fits a bigint primary key
# Real zones lie within UTC-12 and UTC+14; PostgreSQL refuses an offset past ±15:59, which
# Python accepts up to ±23:59, so a wider one would fail only inside the query.
MAX_OFFSET = dt.timedelta(hours=14)
# A day inside either end keeps the value, and any offset added to it, within the years
# both Python and the databases hold.
EARLIEST = dt.datetime(1, 1, 2, tzinfo=dt.UTC)
LATEST = dt.datetime(9999, 12, 30, tzinfo=dt.UTC)


class BadParameter(Invalid):
    """A query parameter the request cannot mean (400); its message names it, as `parameter` does."""

    code = "bad-parameter"

    def __init__(self, name: str, message: str) -> None:
        super().__init__(message, extra={"parameter": name})
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
    aware = timezone.make_aware(parsed) if timezone.is_naive(parsed) else parsed
    offset = aware.utcoffset() or dt.timedelta()
    if abs(offset) > MAX_OFFSET:
        raise BadParameter(
            name,
            f"{name} has the UTC offset {_hours(offset)}; offsets lie within -14:00 and +14:00.",
        )
    if not EARLIEST <= aware <= LATEST:
        raise BadParameter(
            name, f"{name} must lie between 0001-01-02 and 9999-12-30, not {value[:40]!r}."
        )
    return aware


def _hours(offset: dt.timedelta) -> str:
    minutes = int(abs(offset).total_seconds()) // 60
    return f"{'-' if offset < dt.timedelta() else '+'}{minutes // 60:02d}:{minutes % 60:02d}"


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
