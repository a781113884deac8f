"""HSTS and the Content-Security-Policy: on every response, the same from Django and Caddy,
and templates that the policy lets work (no inline script or style anywhere).

The browser test (tests/browser/test_content_security_policy.py) opens every page under
the policy; these check the headers and the templates without one.
"""

from __future__ import annotations

import importlib
import re
from pathlib import Path
from types import ModuleType

import pytest
from django.conf import settings
from django.contrib.auth.models import User
from django.test import Client, override_settings

from hrc.middleware import policy_header
from hrc.organisations.models import Organisation

ROOT = Path(settings.BASE_DIR)
POLICY = policy_header(settings.HRC_CONTENT_SECURITY_POLICY)
HSTS = "max-age=31536000; includeSubDomains"
HSTS_SETTINGS = (
    "SECURE_HSTS_SECONDS",
    "SECURE_HSTS_INCLUDE_SUBDOMAINS",
    "SECURE_HSTS_PRELOAD",
    "SECURE_SSL_REDIRECT",
    "SECURE_PROXY_SSL_HEADER",
)
# Each role's pages, the sign-in page and the API (HTML and JSON).
PAGES: dict[str, list[str]] = {
    "anonymous": ["/accounts/login/", "/admin/login/", "/api/auth/login/"],
    "operator": ["/tablet/", "/api/work-items/"],
    "engineer": [
        "/",
        "/patterns/",
        "/patterns/new/",
        "/cases/",
        "/cases/new/",
        "/incidents/",
        "/analytics/",
        "/cobots/",
        "/api/",
        "/api/cases/",
        "/api/docs/",
        "/api/docs/?script",
    ],
    "admin": ["/organisation/people/", "/organisation/teams/", "/organisation/cells/"],
}


def _client(user: User | None) -> Client:
    client = Client()
    if user is not None:
        client.force_login(user)
    return client


@pytest.mark.django_db
@pytest.mark.parametrize("role", list(PAGES))
def test_every_page_and_api_answer_carries_the_policy(
    role: str, organisation: Organisation, operator: User, engineer: User, admin: User
) -> None:
    client = _client(
        {"anonymous": None, "operator": operator, "engineer": engineer, "admin": admin}[role]
    )
    for path in PAGES[role]:
        response = client.get(path, HTTP_ACCEPT="text/html")
        assert response.status_code == 200, path
        assert response["Content-Security-Policy"] == POLICY, path


@pytest.mark.django_db
def test_the_policy_admits_only_the_sites_own_scripts_and_styles() -> None:
    policy = settings.HRC_CONTENT_SECURITY_POLICY
    assert policy["script-src"] == ["'self'"]
    assert policy["style-src"] == ["'self'"]
    assert policy["frame-ancestors"] == ["'none'"]
    assert policy["object-src"] == ["'none'"]
    # A refusal (404, 403) is a page too.
    response = Client().get("/no-such-page/")
    assert response.status_code == 404
    assert response["Content-Security-Policy"] == POLICY


@pytest.mark.django_db
def test_redoc_alone_admits_inline_styles_and_blob_workers_but_no_other_script(
    engineer: User,
) -> None:
    response = _client(engineer).get("/api/redoc/")

    assert response.status_code == 200
    directives = dict(
        part.split(" ", 1) for part in response["Content-Security-Policy"].split("; ")
    )
    assert directives["style-src"] == "'self' 'unsafe-inline'"
    assert directives["worker-src"] == "'self' blob:"
    assert directives["script-src"] == "'self'"
    assert directives["img-src"] == "'self' data:"


def _prod_settings(monkeypatch: pytest.MonkeyPatch) -> ModuleType:
    monkeypatch.setenv("SECRET_KEY", "test-only-not-secret")
    return importlib.reload(importlib.import_module("hrc.settings.prod"))


@pytest.mark.django_db
def test_production_sends_hsts_over_https_behind_the_proxy(
    monkeypatch: pytest.MonkeyPatch, engineer: User
) -> None:
    prod = _prod_settings(monkeypatch)
    assert prod.SECURE_HSTS_PRELOAD is False
    with override_settings(**{name: getattr(prod, name) for name in HSTS_SETTINGS}):
        client = _client(engineer)
        for path in ("/accounts/login/", "/cases/", "/api/cases/"):
            # Caddy says the browser's request came over HTTPS.
            response = client.get(path, HTTP_X_FORWARDED_PROTO="https")
            assert response.status_code == 200, path
            assert response["Strict-Transport-Security"] == HSTS, path
            assert response["Content-Security-Policy"] == POLICY, path


@pytest.mark.django_db
def test_production_redirects_plain_http_yet_the_health_check_is_answered(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    prod = _prod_settings(monkeypatch)
    with override_settings(**{name: getattr(prod, name) for name in HSTS_SETTINGS}):
        client = Client()
        response = client.get("/accounts/login/")
        assert response.status_code == 301
        assert response["Location"] == "https://testserver/accounts/login/"
        # docker/healthcheck.py asks daphne directly, saying HTTPS as the proxy would.
        checked = client.get("/accounts/login/", HTTP_X_FORWARDED_PROTO="https")
        assert checked.status_code == 200


def test_caddy_sends_the_same_policy_and_hsts_for_what_it_serves() -> None:
    caddyfile = (ROOT / "docker" / "Caddyfile").read_text()

    headers = dict(re.findall(r'^\s*\?([\w-]+) "([^"]*)"$', caddyfile, re.MULTILINE))

    assert headers["Content-Security-Policy"] == POLICY
    assert headers["Strict-Transport-Security"] == HSTS


# What the policy refuses, as it would appear in a template.
INLINE = {
    "inline <style>": re.compile(r"<style\b", re.IGNORECASE),
    # Not where a template cuts one out of DRF's markup (rest_framework/api.html).
    "style attribute": re.compile(r"(?<!cut:')\sstyle\s*=", re.IGNORECASE),
    "on… handler": re.compile(r"\son[a-z]+\s*=", re.IGNORECASE),
    "javascript: URL": re.compile(r"javascript:", re.IGNORECASE),
}
# A <script> with neither src nor a JSON type runs inline code.
SCRIPT = re.compile(r"<script\b(?![^>]*\bsrc=)(?![^>]*type=\"application/json\")[^>]*>", re.I)
COMMENT = re.compile(r"{% comment %}.*?{% endcomment %}|{#.*?#}", re.DOTALL)


@pytest.mark.parametrize(
    "template", sorted((ROOT / "templates").rglob("*.html")), ids=lambda path: path.name
)
def test_no_template_has_inline_script_or_style(template: Path) -> None:
    text = COMMENT.sub("", template.read_text())
    found = [name for name, pattern in INLINE.items() if pattern.search(text)]
    if SCRIPT.search(text):
        found.append("inline <script>")
    assert not found, f"{template.relative_to(ROOT)}: {found}"
