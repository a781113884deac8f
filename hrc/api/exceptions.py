"""One error format for the whole API: `{"detail": str, ...}` with a 4xx status.

DRF already turns its own exceptions into 4xx; this adds the Django ones a
view can raise (a request body over the size limit, a bad multipart) so that
bad input never reaches the client as a 500 with a traceback.
"""

from typing import Any

from django.core.exceptions import RequestDataTooBig, SuspiciousOperation
from rest_framework import status
from rest_framework.response import Response
from rest_framework.views import exception_handler as drf_exception_handler


def exception_handler(exc: Exception, context: dict[str, Any]) -> Response | None:
    """DRF's handler, plus 413 for oversized bodies and 400 for suspicious requests."""
    if isinstance(exc, RequestDataTooBig):
        return Response(
            {"detail": "The request body is too large (the limit is 2 MiB)."},
            status=status.HTTP_413_REQUEST_ENTITY_TOO_LARGE,
        )
    if isinstance(exc, SuspiciousOperation):
        return Response({"detail": str(exc)}, status=status.HTTP_400_BAD_REQUEST)
    return drf_exception_handler(exc, context)
