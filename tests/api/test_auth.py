"""Token and session authentication, and the OpenAPI schema."""

from pathlib import Path

import pytest
from django.contrib.auth.models import User
from django.core.management import call_command
from rest_framework.authtoken.models import Token
from rest_framework.test import APIClient

from hrc.patterns.models import PatternModel
from tests import factories


def test_an_integrator_authenticates_with_a_token(engineer: User, pattern: PatternModel) -> None:
    token = Token.objects.create(user=engineer)
    client = APIClient()
    client.credentials(HTTP_AUTHORIZATION=f"Token {token.key}")
    response = client.get("/api/patterns/")
    assert response.status_code == 200
    assert response.data["count"] == 1


def test_an_integrator_trades_credentials_for_a_token_once(engineer: User) -> None:
    client = APIClient()

    response = client.post(
        "/api/token/",
        {"username": engineer.username, "password": factories.PASSWORD},
        format="json",
    )

    assert response.status_code == 200
    assert response.data["token"] == Token.objects.get(user=engineer).key


def test_wrong_credentials_get_no_token_and_a_message(engineer: User) -> None:
    response = APIClient().post(
        "/api/token/", {"username": engineer.username, "password": "wrong"}, format="json"
    )

    assert response.status_code == 400
    assert "Unable to log in" in str(response.data)
    assert not Token.objects.filter(user=engineer).exists()


def test_a_wrong_token_is_refused(db: None) -> None:
    client = APIClient()
    client.credentials(HTTP_AUTHORIZATION="Token not-a-real-token")
    response = client.get("/api/patterns/")
    # 401 with a challenge: token authentication comes first, so DRF answers as it would.
    assert response.status_code == 401
    assert response["WWW-Authenticate"] == "Token"
    assert response.data["detail"] == "Invalid token."


def test_a_browser_session_reads_and_needs_csrf_to_write(engineer: User) -> None:
    client = APIClient(enforce_csrf_checks=True)
    assert client.login(username=engineer.username, password=factories.PASSWORD)
    assert client.get("/api/patterns/").status_code == 200
    response = client.post("/api/patterns/", {"name": "x"}, format="json")
    assert response.status_code == 403
    assert "CSRF" in response.data["detail"]
    assert not PatternModel.objects.exists()


@pytest.mark.django_db
def test_the_schema_is_served() -> None:
    response = APIClient().get("/api/schema/")
    assert response.status_code == 200
    assert b"/api/patterns/{id}/publish/" in response.content


@pytest.mark.django_db
def test_the_schema_generates_without_warnings(tmp_path: Path) -> None:
    # --fail-on-warn turns every drf-spectacular warning (an unresolvable
    # serializer, a guessed path parameter) into a failure.
    call_command("spectacular", "--fail-on-warn", "--file", str(tmp_path / "schema.yaml"))
    assert "/api/cobots/" in (tmp_path / "schema.yaml").read_text()


@pytest.mark.django_db
def test_the_docs_page_is_served() -> None:
    assert APIClient().get("/api/docs/").status_code == 200
