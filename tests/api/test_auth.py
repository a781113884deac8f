"""API keys, session authentication, login lockout on every path, and the OpenAPI schema."""

import datetime as dt
from pathlib import Path

import pytest
from axes.models import AccessAttempt
from django.contrib.auth.models import User
from django.core.management import call_command
from django.http import HttpRequest
from django.test import Client
from django.utils import timezone
from rest_framework.test import APIClient

from hrc import signin
from hrc.organisations import services
from hrc.organisations.models import ApiToken, Membership
from hrc.patterns.models import PatternModel
from tests import factories


def keyed(key: str) -> APIClient:
    client = APIClient()
    client.credentials(HTTP_AUTHORIZATION=f"Token {key}")
    return client


def test_an_integrator_authenticates_with_a_key(engineer: User, pattern: PatternModel) -> None:
    response = keyed(factories.api_key(engineer)).get("/api/patterns/")
    assert response.status_code == 200
    assert response.data["count"] == 1


def test_an_integrator_trades_credentials_for_a_key_that_expires(engineer: User) -> None:
    response = APIClient().post(
        "/api/token/",
        {"username": engineer.username, "password": factories.PASSWORD},
        format="json",
    )

    assert response.status_code == 200
    key = response.data["token"]
    [token] = ApiToken.objects.filter(user=engineer)
    assert token.digest == services.digest_of(key) != key  # only the digest is kept
    expires = dt.datetime.fromisoformat(response.data["expires_at"])
    assert abs(expires - (timezone.now() + dt.timedelta(days=7))) < dt.timedelta(minutes=1)
    assert keyed(key).get("/api/patterns/").status_code == 200


def test_each_request_for_a_key_gets_a_new_one_and_the_old_ones_keep_working(
    engineer: User,
) -> None:
    first, second = factories.api_key(engineer), factories.api_key(engineer)
    assert first != second
    assert keyed(first).get("/api/patterns/").status_code == 200
    assert keyed(second).get("/api/patterns/").status_code == 200


def test_an_expired_key_is_refused_with_what_to_do(engineer: User) -> None:
    key = factories.api_key(engineer)
    ApiToken.objects.filter(user=engineer).update(expires_at=timezone.now())

    response = keyed(key).get("/api/patterns/")

    assert response.status_code == 401
    assert "expired" in response.data["detail"]
    assert "POST /api/token/" in response.data["detail"]


def test_a_new_password_ends_every_key_of_the_user(engineer: User, operator: User) -> None:
    keys = [factories.api_key(engineer), factories.api_key(engineer)]
    kept = factories.api_key(operator)

    engineer.set_password("a-brand-new-password")
    engineer.save()

    for key in keys:
        assert keyed(key).get("/api/patterns/").status_code == 401
    assert keyed(kept).get("/api/patterns/").status_code == 200


def test_a_password_reset_by_an_admin_ends_every_key(engineer: User, admin: User) -> None:
    key = factories.api_key(engineer)
    membership = Membership.objects.get(user=engineer)

    services.reset_member_password(membership, by=admin)

    assert keys_left(engineer) == 0
    assert keyed(key).get("/api/patterns/").status_code == 401


def test_saving_a_user_without_a_new_password_keeps_their_keys(engineer: User) -> None:
    key = factories.api_key(engineer)
    engineer.first_name = "Erik"
    engineer.save()
    assert keyed(key).get("/api/patterns/").status_code == 200


def test_deactivating_a_member_ends_their_keys(engineer: User, admin: User) -> None:
    key = factories.api_key(engineer)
    services.deactivate_member(Membership.objects.get(user=engineer), by=admin)
    assert keyed(key).get("/api/patterns/").status_code == 401
    assert keys_left(engineer) == 0


def test_removing_a_member_ends_their_keys(engineer: User) -> None:
    key = factories.api_key(engineer)
    services.remove_member(Membership.objects.get(user=engineer))
    assert keys_left(engineer) == 0
    assert keyed(key).get("/api/patterns/").status_code == 401


def test_wrong_credentials_get_no_key_and_a_message(engineer: User) -> None:
    response = APIClient().post(
        "/api/token/", {"username": engineer.username, "password": "wrong"}, format="json"
    )

    assert response.status_code == 400
    assert "Unable to log in" in str(response.data)
    assert keys_left(engineer) == 0


def test_a_wrong_key_is_refused(db: None) -> None:
    response = keyed("not-a-real-token").get("/api/patterns/")
    # 401 with a challenge: token authentication comes first, so DRF answers as it would.
    assert response.status_code == 401
    assert response["WWW-Authenticate"] == "Token"
    assert "Invalid or expired token" in response.data["detail"]


def keys_left(user: User) -> int:
    return ApiToken.objects.filter(user=user).count()


# Guessing passwords ------------------------------------------------------------------------

GUESSES = 20


def guess_by_api(client: Client, username: str, password: str) -> int:
    body = {"username": username, "password": password}
    return client.post("/api/token/", body, content_type="application/json").status_code


def guess_by_login_page(client: Client, username: str, password: str) -> int:
    return client.post("/accounts/login/", {"username": username, "password": password}).status_code


def guess_by_admin_login(client: Client, username: str, password: str) -> int:
    body = {"username": username, "password": password, "next": "/admin/"}
    return client.post("/admin/login/", body).status_code


def guess_by_browsable_api_login(client: Client, username: str, password: str) -> int:
    body = {"username": username, "password": password, "next": "/api/"}
    return client.post("/api/auth/login/", body).status_code


@pytest.mark.parametrize(
    "guess",
    [guess_by_api, guess_by_login_page, guess_by_admin_login, guess_by_browsable_api_login],
)
def test_twenty_wrong_passwords_from_one_address_in_a_minute_are_locked_out(
    engineer: User, admin: User, guess: object
) -> None:
    client = Client(REMOTE_ADDR="203.0.113.7")
    answers = [guess(client, engineer.username, f"guess-{n}") for n in range(GUESSES)]  # type: ignore[operator]

    assert answers.count(429) >= GUESSES // 2
    assert answers[-1] == 429
    if guess is guess_by_login_page:
        page = client.post("/accounts/login/", {"username": "x", "password": "y"})
        assert b"Sign-in locked" in page.content
    # Locked out means locked out: not even the right password, nor another person's, gets in.
    assert guess(client, engineer.username, factories.PASSWORD) == 429  # type: ignore[operator]
    assert guess(client, admin.username, factories.PASSWORD) == 429  # type: ignore[operator]
    # Another address is not punished for this one's guesses.
    assert guess(Client(REMOTE_ADDR="203.0.113.8"), engineer.username, "wrong") != 429  # type: ignore[operator]


def test_a_forwarded_for_header_does_not_hide_the_guesser_without_a_proxy(engineer: User) -> None:
    answers = [
        guess_by_api(
            Client(REMOTE_ADDR="203.0.113.9", HTTP_X_FORWARDED_FOR=f"10.0.0.{n}"),
            engineer.username,
            "x",
        )
        for n in range(GUESSES)
    ]
    assert answers[-1] == 429


def test_each_lockout_in_a_day_doubles_the_next_cool_off(engineer: User) -> None:
    client = Client(REMOTE_ADDR="203.0.113.10")
    lockouts = []
    for _ in range(3):
        answers = [guess_by_api(client, engineer.username, "wrong") for _ in range(10)]
        assert answers[-1] == 429
        request = HttpRequest()
        request.axes_ip_address = "203.0.113.10"  # type: ignore[attr-defined]  # as axes sets it
        lockouts.append(signin.cool_off(request))
        # The cool-off passes: the address's attempts are as old as it.
        AccessAttempt.objects.all().delete()

    assert lockouts == [dt.timedelta(minutes=1), dt.timedelta(minutes=2), dt.timedelta(minutes=4)]


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
