"""One error format for the whole API: `{"detail": str, ...}` with a 4xx status.

DRF already turns its own exceptions into 4xx; this adds the Django, engine and
service ones a view can raise (a request body over the size limit, a model
rule, a document that is not `hrc-pattern/1`, any refusal of `hrc.errors` with
its status and code) so that bad input never reaches the client as a 500 with a
traceback, and no view catches a service's refusal itself. Field errors keep
DRF's shape under `fields`.
"""

from typing import Any

from django.core.exceptions import RequestDataTooBig, SuspiciousOperation
from django.core.exceptions import ValidationError as DjangoValidationError
from django.db.models import ProtectedError
from rest_framework import exceptions, status
from rest_framework.exceptions import Throttled
from rest_framework.response import Response
from rest_framework.views import exception_handler as drf_exception_handler

from hrc.engine import FormatError
from hrc.errors import Busy, Refusal


class Rejected(exceptions.APIException):
    """A refusal whose body is `payload` as given: booleans and numbers stay what they are.

    (DRF's own exceptions turn every leaf of their detail into a string.)
    """

    status_code: int = status.HTTP_400_BAD_REQUEST

    def __init__(
        self, payload: dict[str, Any], status_code: int = status.HTTP_400_BAD_REQUEST
    ) -> None:
        super().__init__(str(payload.get("detail", "")))
        self.payload = payload
        self.status_code = status_code


def document_rejected(exc: FormatError) -> Rejected:
    """A 400 listing every issue that keeps the body from being read as a pattern."""
    return Rejected(
        {
            "detail": f"The document is not a readable hrc-pattern/1 document: {exc}",
            "errors": [issue.as_dict() for issue in exc.issues],
        }
    )


def exception_handler(exc: Exception, context: dict[str, Any]) -> Response | None:
    """DRF's handler, plus the Django and engine exceptions, all in the one format."""
    if isinstance(exc, RequestDataTooBig):
        return Response(
            {"detail": "The request body is too large (the limit is 2 MiB)."},
            status=status.HTTP_413_REQUEST_ENTITY_TOO_LARGE,
        )
    if isinstance(exc, SuspiciousOperation):
        return Response({"detail": str(exc)}, status=status.HTTP_400_BAD_REQUEST)
    if isinstance(exc, FormatError):
        exc = document_rejected(exc)
    if isinstance(exc, Refusal):
        return refusal_response(exc, context)
    if isinstance(exc, Rejected):
        return Response(exc.payload, status=exc.status_code)
    if isinstance(exc, DjangoValidationError):
        detail = exc.message_dict if hasattr(exc, "error_dict") else exc.messages
        exc = exceptions.ValidationError(detail)
    if isinstance(exc, ProtectedError):
        return Response(
            {"detail": "Other records depend on this one, so it cannot be deleted."},
            status=status.HTTP_409_CONFLICT,
        )
    response = drf_exception_handler(exc, context)
    if response is not None and isinstance(exc, exceptions.ValidationError):
        response.data = _with_summary(response.data)
    return response


def refusal_response(refusal: Refusal, context: dict[str, Any]) -> Response:
    """The refusal's body with its status and headers; `{"detail", "code", ...}`."""
    if isinstance(refusal, Busy):
        # DRF's own 429, whose detail also says when to try again, as throttling answers.
        throttled = drf_exception_handler(
            Throttled(wait=refusal.retry_after, detail=str(refusal)), context
        )
        assert throttled is not None  # DRF answers every APIException
        throttled.data["code"] = refusal.code
        return throttled
    return Response(refusal.body(), status=refusal.status, headers=refusal.headers())


# Where DRF and Django put errors that belong to no single field.
NON_FIELD_KEYS = frozenset({"non_field_errors", "__all__"})


def _with_summary(data: Any) -> dict[str, Any]:
    """`{"detail": first message, "fields": DRF's field errors}`; lists become the detail."""
    if isinstance(data, dict):
        first = _first_message(data)
        return {"detail": f"Invalid input: {first}" if first else "Invalid input.", "fields": data}
    if isinstance(data, list):
        return {"detail": " ".join(str(item) for item in data) or "Invalid input."}
    return {"detail": str(data)}


def _first_message(data: Any, path: str = "") -> str:
    if isinstance(data, dict):
        for key, value in data.items():
            found = _first_message(value, f"{path}.{key}" if path else str(key))
            if found:
                return found
        return ""
    if isinstance(data, list):
        for item in data:
            found = _first_message(item, path)
            if found:
                return found
        return ""
    return f"{path}: {data}" if path and path not in NON_FIELD_KEYS else str(data)
