"""The API's root (/api/), listing its endpoints, its answer for an address it lacks, and
the door for machines: API keys."""

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
from django.views.decorators.csrf import csrf_exempt
from drf_spectacular.utils import extend_schema
from rest_framework import serializers
from rest_framework.authtoken.serializers import AuthTokenSerializer
from rest_framework.exceptions import Throttled, ValidationError
from rest_framework.permissions import AllowAny
from rest_framework.request import Request
from rest_framework.response import Response
from rest_framework.views import APIView

from hrc.organisations import services

# The API's own documents, served beside it in hrc/urls.py.
DOCUMENTS = {"schema": "api-schema", "docs": "api-docs", "redoc": "api-redoc", "token": "api-token"}


class ApiKeySerializer(serializers.Serializer[Any]):
    token = serializers.CharField(help_text="The key; only its digest is kept, so keep it safe.")
    expires_at = serializers.DateTimeField(help_text="From then on the key is refused.")


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


@csrf_exempt  # it changes nothing; a machine's POST to a wrong address learns the address is wrong
def api_not_found(request: HttpRequest, *args: Any, **kwargs: Any) -> JsonResponse:
    """A 404 in the API's error format for an address under /api/ that nothing serves."""
    detail = f"No API endpoint at {request.path}."
    if not request.path.endswith("/") and _serves(request.path + "/"):
        detail += f" Did you mean {request.path}/?"
    return JsonResponse({"detail": f"{detail} The endpoints are listed at /api/."}, status=404)


class LockedOut(Throttled):
    default_detail = (
        "Too many wrong passwords from this address; sign-in is locked for a while. "
        "Try again later, or ask an admin."
    )


class TokenView(APIView):
    """`POST /api/token/` with `username` and `password`: a new API key, shown once."""

    authentication_classes: list[type] = []  # credentials in the body, not a session
    permission_classes = [AllowAny]
    serializer_class = AuthTokenSerializer

    @extend_schema(request=AuthTokenSerializer, responses={200: ApiKeySerializer})
    def post(self, request: Request) -> Response:
        """A new key for `Authorization: Token <key>`, valid until `expires_at`; every key of
        the user stops working when their password changes or their membership ends. Ten
        wrong passwords from one address lock it out (429) for a while (hrc.signin)."""
        serializer = AuthTokenSerializer(data=request.data, context={"request": request})
        valid = serializer.is_valid()
        # axes marks the request it was given, DRF's, where its middleware cannot see it.
        if getattr(request, "axes_locked_out", False):
            raise LockedOut()
        if not valid:
            raise ValidationError(serializer.errors)
        key, token = services.issue_api_token(serializer.validated_data["user"])
        return Response(ApiKeySerializer({"token": key, "expires_at": token.expires_at}).data)
