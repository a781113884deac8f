"""The editor's pages: the pattern list, a new pattern, editing one, behind the wall and the roles."""

import json
import re
from typing import Any

import pytest
from django.contrib.auth.models import User
from django.test import Client

from hrc.engine.taskconfig import DEVICE_CALLS
from hrc.organisations.models import Organisation
from hrc.patterns.models import PatternModel
from hrc.patterns.services import retire_version
from tests import factories

pytestmark = pytest.mark.django_db


def _browser(user: User) -> Client:
    client = Client()
    client.force_login(user)
    return client


def _config(html: str) -> dict[str, Any]:
    match = re.search(
        r'<script id="hrc-editor-config" type="application/json">(.*?)</script>', html, re.S
    )
    assert match, "the page carries no editor configuration"
    return dict(json.loads(match.group(1)))


@pytest.mark.parametrize("path", ["/patterns/", "/patterns/new/", "/patterns/1/edit/"])
def test_a_visitor_who_is_not_signed_in_is_sent_to_sign_in(path: str) -> None:
    response = Client().get(path)
    assert response.status_code == 302
    assert response["Location"].startswith("/accounts/login/")


def test_an_engineer_opens_a_draft_in_the_editor(engineer: User, pattern: PatternModel) -> None:
    response = _browser(engineer).get(f"/patterns/{pattern.pk}/edit/")
    assert response.status_code == 200
    html = response.content.decode()
    assert "hrc/editor.js" in html
    config = _config(html)
    assert config["draft"] == pattern.draft
    assert config["pattern"] == {
        "id": pattern.pk,
        "name": "Hand-over",
        "canWrite": True,
        "organisation": pattern.organisation_id,
        "latestVersion": None,
    }
    assert "csrftoken" in response.cookies
    # The device calls the properties panel offers are the engine's.
    assert config["deviceCalls"] == {
        name: list(arguments) for name, (_, arguments, _) in DEVICE_CALLS.items()
    }


def test_a_new_pattern_opens_an_empty_editor_for_the_organisation(
    admin: User, organisation: Organisation
) -> None:
    response = _browser(admin).get("/patterns/new/")
    assert response.status_code == 200
    config = _config(response.content.decode())
    assert config["draft"] is None
    assert "recognition.gesture" in config["deviceCalls"]
    assert config["pattern"] == {
        "id": None,
        "name": "New pattern",
        "canWrite": True,
        "organisation": organisation.pk,
    }


def test_an_operator_reads_the_list_but_may_not_edit(operator: User, pattern: PatternModel) -> None:
    browser = _browser(operator)
    listing = browser.get("/patterns/").content.decode()
    assert "Hand-over" in listing
    assert f"/patterns/{pattern.pk}/edit/" not in listing
    assert "New pattern" not in listing
    for path in (f"/patterns/{pattern.pk}/edit/", "/patterns/new/"):
        response = browser.get(path)
        assert response.status_code == 403
        assert "Only engineers and admins" in response.content.decode()


def test_an_outsider_gets_404_and_sees_none_of_our_patterns(
    outsider: User, pattern: PatternModel, other_organisation: Organisation
) -> None:
    browser = _browser(outsider)
    assert browser.get(f"/patterns/{pattern.pk}/edit/").status_code == 404
    assert "Hand-over" not in browser.get("/patterns/").content.decode()
    # Nor can a new pattern be aimed at our organisation.
    response = browser.get(f"/patterns/new/?organisation={pattern.organisation_id}")
    assert response.status_code == 403


def test_the_list_shows_each_writable_organisation_its_new_link(
    engineer: User, organisation: Organisation, other_organisation: Organisation
) -> None:
    from hrc.organisations import services
    from hrc.organisations.choices import Role

    services.add_member(other_organisation, engineer, Role.ENGINEER)
    factories.make_pattern(other_organisation, name="Their pattern")
    listing = _browser(engineer).get("/patterns/").content.decode()
    assert f"/patterns/new/?organisation={organisation.pk}" in listing
    assert f"/patterns/new/?organisation={other_organisation.pk}" in listing
    assert "Their pattern" in listing


def test_someone_in_no_organisation_sees_an_empty_list_and_may_not_create(loner: User) -> None:
    browser = _browser(loner)
    assert "No patterns yet." in browser.get("/patterns/").content.decode()
    assert browser.get("/patterns/new/").status_code == 403


def test_the_start_page_links_to_the_patterns(engineer: User) -> None:
    assert 'href="/patterns/"' in _browser(engineer).get("/").content.decode()


# The list: class, versions, archive --------------------------------------------------------


def test_the_list_shows_each_patterns_class_and_versions_and_starts_the_newest_in_service(
    engineer: User, organisation: Organisation
) -> None:
    version = factories.make_version(organisation, published_by=engineer)
    html = _browser(engineer).get("/patterns/").content.decode()
    assert '<span class="class">Synchronized</span>' in html
    assert f'href="/patterns/versions/{version.pk}/"' in html
    assert f'href="/cases/new/?version={version.pk}"' in html
    retire_version(version, retired=True)
    html = _browser(engineer).get("/patterns/").content.decode()
    assert f"/cases/new/?version={version.pk}" not in html


def test_an_archived_pattern_is_listed_only_on_request_and_comes_back(
    engineer: User, pattern: PatternModel
) -> None:
    client = _browser(engineer)
    archived = client.post(f"/patterns/{pattern.pk}/archive/", {"archive": "1"})
    assert archived.status_code == 302
    assert "Hand-over" not in client.get("/patterns/").content.decode()
    assert "Hand-over" in client.get("/patterns/?archived=1").content.decode()
    client.post(f"/patterns/{pattern.pk}/archive/", {"archive": "0"})
    pattern.refresh_from_db()
    assert pattern.archived_at is None


def test_only_writers_of_the_organisation_archive(
    operator: User, outsider: User, pattern: PatternModel
) -> None:
    assert (
        _browser(outsider).post(f"/patterns/{pattern.pk}/archive/", {"archive": "1"}).status_code
        == 404
    )
    assert (
        _browser(operator).post(f"/patterns/{pattern.pk}/archive/", {"archive": "1"}).status_code
        == 403
    )
    pattern.refresh_from_db()
    assert pattern.archived_at is None


def test_a_new_pattern_for_an_organisation_in_other_digits_than_ascii_goes_to_the_default(
    engineer: User, organisation: Organisation
) -> None:
    response = _browser(engineer).get("/patterns/new/?organisation=%C2%B2")  # "²"
    assert response.status_code == 200
    assert _config(response.content.decode())["pattern"]["organisation"] == organisation.pk
