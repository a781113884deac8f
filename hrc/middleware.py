"""The project's own middleware: a policy header on every response, a 503 for a database that is
down, and the pages' answer to a refusal (hrc.errors).

A database that cannot be reached answers 503 with a message, never a 500 with a traceback.

PostgreSQL restarting or unreachable, or this process's pool exhausted for
HRC_DB_POOL_TIMEOUT seconds, raises OperationalError (or InterfaceError)
wherever a request first touches the database: in DRF's authentication, a
service, a template. The client gets a 503 naming the cause, with
Retry-After; the error goes to the log for whoever runs the server. Last in
MIDDLEWARE, so it sees the exception first.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Mapping, Sequence
from functools import wraps
from typing import Any

from django.conf import settings
from django.db import InterfaceError, OperationalError
from django.http import HttpRequest, HttpResponse, JsonResponse
from django.shortcuts import render
from django.template.loader import render_to_string

from hrc.errors import Refusal

logger = logging.getLogger(__name__)
View = Callable[..., HttpResponse]

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


class RefusalMiddleware:
    """Answers a refusal a page view lets through: the refused page with its message and status.

    The API's views answer theirs in DRF (hrc.api.exceptions), so none arrives here
    from them; a plain Django view under /api/ gets the same JSON body.
    """

    def __init__(self, get_response: Callable[[HttpRequest], HttpResponse]) -> None:
        self.get_response = get_response

    def __call__(self, request: HttpRequest) -> HttpResponse:
        return self.get_response(request)

    def process_exception(self, request: HttpRequest, exception: Exception) -> HttpResponse | None:
        if not isinstance(exception, Refusal):
            return None
        response: HttpResponse
        if request.path.startswith("/api/"):
            response = JsonResponse(exception.body(), status=exception.status)
        else:
            context = {"message": str(exception)}
            response = render(request, "refused.html", context, status=exception.status)
        for name, value in exception.headers().items():
            response[name] = value
        return response


def policy_header(directives: Mapping[str, Sequence[str]]) -> str:
    """The header's value: `default-src 'self'; img-src 'self' data:` from a mapping like
    settings.HRC_CONTENT_SECURITY_POLICY."""
    return "; ".join(f"{name} {' '.join(sources)}" for name, sources in directives.items())


class ContentSecurityPolicyMiddleware:
    """Sends settings.HRC_CONTENT_SECURITY_POLICY with every response that has no policy of its own.

    Django 5.2 has no CSP support of its own (6.0 has). A fixed policy needs no nonces, so
    these lines do what the django-csp package would, with one dependency fewer.
    A view that needs another policy sets the header itself (`content_security_policy`).
    """

    def __init__(self, get_response: Callable[[HttpRequest], HttpResponse]) -> None:
        self.get_response = get_response
        self.policy = policy_header(settings.HRC_CONTENT_SECURITY_POLICY)

    def __call__(self, request: HttpRequest) -> HttpResponse:
        response = self.get_response(request)
        response.headers.setdefault("Content-Security-Policy", self.policy)
        return response


def content_security_policy(**directives: Sequence[str]) -> Callable[[View], View]:
    """A view decorator: the site's policy with the named directives replaced, e.g.
    `style_src=["'self'", "'unsafe-inline'"]` for a page whose library injects its styles."""
    replaced = {name.replace("_", "-"): sources for name, sources in directives.items()}

    def decorate(view: View) -> View:
        @wraps(view)
        def with_policy(request: HttpRequest, *args: Any, **kwargs: Any) -> HttpResponse:
            response = view(request, *args, **kwargs)
            response.headers["Content-Security-Policy"] = policy_header(
                {**settings.HRC_CONTENT_SECURITY_POLICY, **replaced}
            )
            return response

        return with_policy

    return decorate
