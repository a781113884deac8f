"""A database that cannot be reached answers 503 with a message, never a 500 with a traceback.

PostgreSQL restarting or unreachable, or this process's pool exhausted for
HRC_DB_POOL_TIMEOUT seconds, raises OperationalError (or InterfaceError)
wherever a request first touches the database: in DRF's authentication, a
service, a template. The client gets a 503 naming the cause, with
Retry-After; the error goes to the log for whoever runs the server. Last in
MIDDLEWARE, so it sees the exception first.
"""

from __future__ import annotations

import logging
from collections.abc import Callable

from django.db import InterfaceError, OperationalError
from django.http import HttpRequest, HttpResponse, JsonResponse
from django.template.loader import render_to_string

logger = logging.getLogger(__name__)

RETRY_AFTER_SECONDS = 5
DETAIL = (
    "The database is not answering (it is restarting, unreachable or overloaded), "
    "so this request could not be served. Try again in a moment."
)


class DatabaseUnavailableMiddleware:
    def __init__(self, get_response: Callable[[HttpRequest], HttpResponse]) -> None:
        self.get_response = get_response

    def __call__(self, request: HttpRequest) -> HttpResponse:
        return self.get_response(request)

    def process_exception(self, request: HttpRequest, exception: Exception) -> HttpResponse | None:
        if not isinstance(exception, OperationalError | InterfaceError):
            return None
        logger.error("%s %s: the database is unavailable: %s", request.method, request.path, exception)  # fmt: skip
        response: HttpResponse
        if request.path.startswith("/api/") or "json" in request.headers.get("Accept", ""):
            response = JsonResponse({"detail": DETAIL}, status=503)
        else:
            # Rendered without the request: its context processors would ask the database again.
            response = HttpResponse(render_to_string("503.html", {"detail": DETAIL}), status=503)
        response["Retry-After"] = str(RETRY_AFTER_SECONDS)
        return response
