"""The API's one way of paging a list: `?limit=` and `?offset=`, both checked before a query runs.

DRF's LimitOffsetPagination passes any `limit` to the database (a bigint overflow
is a 500) and quietly ignores one it cannot read; here a limit over MAX_LIMIT is
cut to it, and anything that is not a plain whole number in range is a 400 that
names the parameter.
"""

import re
from typing import Any

from rest_framework.pagination import LimitOffsetPagination
from rest_framework.request import Request

from hrc.api.exceptions import Rejected

# The largest page: above the demo's `?limit=1000` request for every pattern.
MAX_LIMIT = 1000
# Past any list the plant will hold; it keeps the number well inside a bigint.
MAX_OFFSET = 1_000_000_000

# ASCII digits only: str.isdigit() and int() also take "²" and "٣".
_DIGITS = re.compile(r"[0-9]+")


class LimitOffset(LimitOffsetPagination):
    """Pages of `limit` rows (PAGE_SIZE unless asked, at most MAX_LIMIT) from `offset`."""

    max_limit = MAX_LIMIT

    def get_limit(self, request: Request) -> int:
        limit = _whole_param(request, self.limit_query_param, minimum=1, largest=MAX_LIMIT)
        if limit is None:
            return int(self.default_limit or MAX_LIMIT)
        return min(limit, MAX_LIMIT)

    def get_offset(self, request: Request) -> int:
        offset = _whole_param(request, self.offset_query_param, minimum=0, largest=MAX_OFFSET)
        if offset is None:
            return 0
        if offset > MAX_OFFSET:
            raise Rejected({"detail": f"offset must be at most {MAX_OFFSET}."})
        return offset

    def get_schema_operation_parameters(self, view: Any) -> list[dict[str, Any]]:
        parameters = super().get_schema_operation_parameters(view)
        bounds = {
            self.limit_query_param: {"minimum": 1},
            self.offset_query_param: {"minimum": 0, "maximum": MAX_OFFSET},
        }
        for parameter in parameters:
            parameter["schema"].update(bounds.get(parameter["name"], {}))
        return parameters


def _whole_param(request: Request, name: str, minimum: int, largest: int) -> int | None:
    """The query parameter as an int; None when absent; a 400 naming it unless it is ASCII
    digits worth `minimum` or more. A number above `largest` reads as `largest + 1`, so one of
    any length is compared without converting it (int() refuses over 4,300 digits)."""
    value = request.query_params.get(name)
    if value is None:
        return None
    if not _DIGITS.fullmatch(value):
        raise Rejected({"detail": f"{name} must be a whole number, {minimum} or more."})
    significant = value.lstrip("0") or "0"
    if len(significant) > len(str(largest)):
        return largest + 1
    number = min(int(significant), largest + 1)
    if number < minimum:
        raise Rejected({"detail": f"{name} must be a whole number, {minimum} or more."})
    return number
