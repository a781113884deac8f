"""One error family (hrc/errors.py) and its two handlers: the API's JSON and the pages' refused page.

The views here raise a refusal and catch nothing, as the project's views do; the
URLs are this module's, put in front of the project's own (`pytest.mark.urls`).
"""

from __future__ import annotations

import ast
from pathlib import Path
from typing import Any

import pytest
from django.contrib.auth.models import User
from django.http import HttpRequest, HttpResponse
from django.test import Client
from django.urls import include, path
from rest_framework.permissions import AllowAny
from rest_framework.request import Request
from rest_framework.response import Response
from rest_framework.test import APIClient
from rest_framework.views import APIView

from hrc.errors import Busy, Conflict, Invalid, NotAllowed, NotFound, Refusal

ROOT = Path(__file__).resolve().parent.parent


class Unreachable(Refusal):
    """A refusal whose status is the instance's, as the cobots' ControlError."""

    code = "unreachable"


REFUSALS: dict[str, Refusal] = {
    "invalid": Invalid.at("batch", "batch must be a number."),
    "not-allowed": NotAllowed("Only engineers do this."),
    "not-found": NotFound("There is no work item 7 in your organisations."),
    "conflict": Conflict("The work item was completed by someone else."),
    "busy": Busy("Every slot is taken: try again in a few seconds.", retry_after=3),
    "unreachable": Unreachable("cobot1 cannot be reached.", status=503, extra={"cobot": 4}),
}


def refuse(request: HttpRequest, kind: str) -> HttpResponse:
    raise REFUSALS[kind]


class RefusingView(APIView):
    permission_classes = [AllowAny]

    def get(self, request: Request, kind: str) -> Response:
        raise REFUSALS[kind]


urlpatterns = [
    path("refusing/<str:kind>/", refuse),
    path("api/refusing/<str:kind>/", RefusingView.as_view()),
    path("api/plain-refusing/<str:kind>/", refuse),
    path("", include("hrc.urls")),
]


# The family --------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("kind", "status"),
    [("invalid", 400), ("not-allowed", 403), ("not-found", 404), ("conflict", 409), ("busy", 429)],
)
def test_each_kind_of_refusal_carries_its_status_and_code(kind: str, status: int) -> None:
    refusal = REFUSALS[kind]

    assert refusal.status == status
    assert refusal.code == kind


def test_a_refusal_may_answer_its_own_status_and_carry_more_of_the_body() -> None:
    refusal = REFUSALS["unreachable"]

    assert refusal.status == 503
    assert Unreachable("x").status == 400  # the class keeps its own
    assert refusal.body() == {
        "detail": "cobot1 cannot be reached.",
        "code": "unreachable",
        "cobot": 4,
    }


def test_an_invalid_input_names_its_fields_and_only_when_there_are_some() -> None:
    assert REFUSALS["invalid"].body() == {
        "detail": "batch must be a number.",
        "code": "invalid",
        "fields": {"batch": ["batch must be a number."]},
    }
    assert Invalid("Say which cases.").body() == {"detail": "Say which cases.", "code": "invalid"}


def test_a_not_found_says_only_its_detail_as_every_other_404() -> None:
    assert REFUSALS["not-found"].body() == {
        "detail": "There is no work item 7 in your organisations."
    }


def test_the_family_imports_nothing_of_hrc_so_every_app_may_raise_it() -> None:
    tree = ast.parse((ROOT / "hrc" / "errors.py").read_text())
    imported = [
        node.module if isinstance(node, ast.ImportFrom) else alias.name
        for node in ast.walk(tree)
        if isinstance(node, ast.Import | ast.ImportFrom)
        for alias in node.names
    ]
    assert imported
    assert not [name for name in imported if name and name.split(".")[0] == "hrc"]


# The API's handler -------------------------------------------------------------------------


@pytest.mark.urls("tests.test_errors")
@pytest.mark.parametrize("kind", ["invalid", "not-allowed", "not-found", "conflict", "unreachable"])
def test_the_api_answers_a_refusal_with_its_status_and_body(db: None, kind: str) -> None:
    response = APIClient().get(f"/api/refusing/{kind}/")

    assert response.status_code == REFUSALS[kind].status
    assert response.json() == REFUSALS[kind].body()


@pytest.mark.urls("tests.test_errors")
def test_the_api_answers_busy_with_429_and_when_to_try_again(db: None) -> None:
    response = APIClient().get("/api/refusing/busy/")

    assert response.status_code == 429
    assert response["Retry-After"] == "3"
    body: dict[str, Any] = response.json()
    assert body["code"] == "busy"
    assert body["detail"].startswith("Every slot is taken: try again in a few seconds.")
    assert "3 seconds" in body["detail"]  # DRF's words for throttling, as before


@pytest.mark.urls("tests.test_errors")
def test_a_plain_django_view_under_api_answers_the_same_json(db: None) -> None:
    response = Client().get("/api/plain-refusing/conflict/")

    assert response.status_code == 409
    assert response.json() == REFUSALS["conflict"].body()


# The pages' handler ------------------------------------------------------------------------


@pytest.mark.urls("tests.test_errors")
@pytest.mark.parametrize("kind", ["invalid", "not-allowed", "not-found", "conflict", "unreachable"])
def test_a_refusal_raised_in_a_page_view_renders_the_refused_page_not_a_500(
    engineer: User, kind: str
) -> None:
    client = Client(raise_request_exception=False)
    client.force_login(engineer)

    response = client.get(f"/refusing/{kind}/")

    assert response.status_code == REFUSALS[kind].status
    assert response_template(response) == "refused.html"
    assert str(REFUSALS[kind]) in response.content.decode()


@pytest.mark.urls("tests.test_errors")
def test_a_busy_page_says_when_to_try_again(engineer: User) -> None:
    client = Client(raise_request_exception=False)
    client.force_login(engineer)

    response = client.get("/refusing/busy/")

    assert response.status_code == 429
    assert response["Retry-After"] == "3"


@pytest.mark.urls("tests.test_errors")
def test_a_refusal_renders_for_someone_signed_out_too(db: None) -> None:
    response = Client(raise_request_exception=False).get("/refusing/not-allowed/")

    assert response.status_code == 403
    assert "Only engineers do this." in response.content.decode()


def test_a_services_refusal_on_a_real_page_is_its_status_not_a_500(
    engineer: User, choice_case: Any
) -> None:
    """The supervisor's cancel of an ended case: the service's Conflict, uncaught by the view."""
    client = Client(raise_request_exception=False)
    client.force_login(engineer)
    url = f"/cases/{choice_case.pk}/control/"
    assert client.post(url, {"action": "cancel", "confirm": "yes"}).status_code == 302

    again = client.post(url, {"action": "suspend"})

    assert again.status_code == 409
    assert response_template(again) == "refused.html"


def response_template(response: Any) -> str:
    """The template the view rendered (the first; the rest are what it extends and includes)."""
    return str(response.templates[0].name)
