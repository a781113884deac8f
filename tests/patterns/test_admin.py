import json

import pytest
from django.contrib.auth.models import User
from django.test import Client

from hrc.organisations.models import Organisation
from hrc.patterns import services
from hrc.patterns.models import PatternModel, PatternVersion
from tests import factories


@pytest.fixture
def version(pattern: PatternModel, engineer: User) -> PatternVersion:
    return services.publish_pattern(pattern, published_by=engineer)


def test_pattern_pages_render(
    staff_client: Client, pattern: PatternModel, version: PatternVersion
) -> None:
    for url in [
        "/admin/patterns/patternmodel/",
        "/admin/patterns/patternmodel/add/",
        f"/admin/patterns/patternmodel/{pattern.pk}/change/",
        "/admin/patterns/patternversion/",
        f"/admin/patterns/patternversion/{version.pk}/change/",
        "/admin/patterns/patternmodel/?q=hand",
        "/admin/patterns/patternversion/?q=erik",
    ]:
        assert staff_client.get(url).status_code == 200, url


def test_the_list_shows_the_latest_version(staff_client: Client, version: PatternVersion) -> None:
    page = staff_client.get("/admin/patterns/patternmodel/").content.decode()
    assert "v1" in page


def test_a_version_page_offers_no_save_and_refuses_a_post(
    staff_client: Client, version: PatternVersion
) -> None:
    url = f"/admin/patterns/patternversion/{version.pk}/change/"
    page = staff_client.get(url).content.decode()
    assert 'name="_save"' not in page
    response = staff_client.post(url, {"number": "9", "document": "{}", "report": "{}"})
    assert response.status_code == 403
    version.refresh_from_db()
    assert version.number == 1


def test_versions_cannot_be_added_or_deleted_in_the_admin(
    staff_client: Client, version: PatternVersion
) -> None:
    assert staff_client.get("/admin/patterns/patternversion/add/").status_code == 403
    delete = f"/admin/patterns/patternversion/{version.pk}/delete/"
    assert staff_client.post(delete, {"post": "yes"}).status_code == 403
    assert PatternVersion.objects.filter(pk=version.pk).exists()


def test_a_published_pattern_cannot_be_deleted_in_the_admin(
    staff_client: Client, pattern: PatternModel, version: PatternVersion
) -> None:
    response = staff_client.post(
        f"/admin/patterns/patternmodel/{pattern.pk}/delete/", {"post": "yes"}
    )
    assert response.status_code == 403
    assert PatternModel.objects.filter(pk=pattern.pk).exists()


def test_the_admin_adds_a_pattern_with_a_valid_draft(
    staff_client: Client, organisation: Organisation
) -> None:
    data = {
        "organisation": str(organisation.pk),
        "name": "From the admin",
        "description": "",
        "draft": json.dumps(factories.valid_document()),
        "versions-TOTAL_FORMS": "0",
        "versions-INITIAL_FORMS": "0",
        "versions-MIN_NUM_FORMS": "0",
        "versions-MAX_NUM_FORMS": "1000",
    }
    response = staff_client.post("/admin/patterns/patternmodel/add/", data)
    assert response.status_code == 302, response.content.decode()[:3000]
    pattern = PatternModel.objects.get(name="From the admin")
    assert pattern.draft == factories.valid_document()
    assert pattern.created_by is not None
    assert pattern.created_by.username == "root"


@pytest.mark.parametrize(
    "draft",
    ['{"format": "hrc-pattern/1", "processes": 5}', '{"name": "nul\\u0000"}', "[1, 2"],
    ids=["wrong-shape", "nul", "not-json"],
)
def test_the_admin_shows_a_bad_draft_as_a_form_error(
    staff_client: Client, organisation: Organisation, draft: str
) -> None:
    data = {
        "organisation": str(organisation.pk),
        "name": "Broken",
        "draft": draft,
        "versions-TOTAL_FORMS": "0",
        "versions-INITIAL_FORMS": "0",
        "versions-MIN_NUM_FORMS": "0",
        "versions-MAX_NUM_FORMS": "1000",
    }
    response = staff_client.post("/admin/patterns/patternmodel/add/", data)
    assert response.status_code == 200
    assert "errorlist" in response.content.decode()
    assert not PatternModel.objects.exists()
