"""The API's root (/api/), listing its endpoints, and its answer for an address it lacks."""

from typing import Any

from django.http import HttpRequest, JsonResponse
from django.urls import (
    NoReverseMatch,
    Resolver404,
    URLPattern,
    URLResolver,
    get_resolver,
    resolve,
    reverse,
)
from drf_spectacular.utils import extend_schema
from rest_framework.permissions import AllowAny
from rest_framework.request import Request
from rest_framework.response import Response
from rest_framework.views import APIView

# The API's own documents, served beside it in hrc/urls.py.
DOCUMENTS = {"schema": "api-schema", "docs": "api-docs", "redoc": "api-redoc", "token": "api-token"}


class ApiRootView(APIView):
    """Every endpoint that needs no id, by its path under /api/; the rest are in the schema."""

    # It names addresses only, as the public schema does.
    permission_classes = [AllowAny]

    @extend_schema(exclude=True)
    def get(self, request: Request) -> Response:
        endpoints = {path.strip("/"): request.build_absolute_uri(path) for path in endpoint_paths()}
        documents = {
            key: request.build_absolute_uri(reverse(name)) for key, name in DOCUMENTS.items()
        }
        return Response({**documents, **dict(sorted(endpoints.items()))})


def endpoint_paths() -> list[str]:
    """The paths under /api/ of the routes in hrc.api.urls that take no argument."""
    root = reverse("api-root")
    paths = set()
    for name in _route_names(get_resolver("hrc.api.urls").url_patterns):
        try:
            url = reverse(name)
        except NoReverseMatch:  # it needs an id
            continue
        if url.startswith(root) and url != root:
            paths.add(url[len(root) :])
    return sorted(paths)


def _route_names(patterns: list[Any]) -> list[str]:
    names: list[str] = []
    for pattern in patterns:
        if isinstance(pattern, URLResolver):
            names += _route_names(pattern.url_patterns)
        elif isinstance(pattern, URLPattern) and pattern.name:
            names.append(pattern.name)
    return names


def _serves(path: str) -> bool:
    try:
        return resolve(path).func is not api_not_found
    except Resolver404:
        return False


def api_not_found(request: HttpRequest, *args: Any, **kwargs: Any) -> JsonResponse:
    """A 404 in the API's error format for an address under /api/ that nothing serves."""
    detail = f"No API endpoint at {request.path}."
    if not request.path.endswith("/") and _serves(request.path + "/"):
        detail += f" Did you mean {request.path}/?"
    return JsonResponse({"detail": f"{detail} The endpoints are listed at /api/."}, status=404)
