"""The patterns API: CRUD of drafts, check, publish, versions, import and export."""

import json
from typing import Any

import pytest
from django.contrib.auth.models import User
from django.test import Client
from rest_framework.test import APIClient

from hrc.engine import read_pattern
from hrc.engine.pnml import pattern_to_pnml
from hrc.organisations.models import Organisation
from hrc.patterns import services
from hrc.patterns.models import PatternModel, PatternVersion
from tests import factories
from tests.hostile_xml import BILLION_LAUGHS, EXTERNAL_ENTITY

MB = 1024 * 1024


def _post_json(client: APIClient, url: str, body: Any) -> Any:
    return client.post(url, json.dumps(body), content_type="application/json")


# Reading ------------------------------------------------------------------------------------


def test_a_member_lists_the_organisations_patterns_without_drafts(
    operator_client: APIClient, pattern: PatternModel, other_organisation: Organisation
) -> None:
    factories.make_pattern(other_organisation, name="Not ours")
    response = operator_client.get("/api/patterns/")
    assert response.status_code == 200
    assert [p["name"] for p in response.data["results"]] == ["Hand-over"]
    assert "draft" not in response.data["results"][0]


def test_a_member_reads_a_pattern_with_its_draft(
    operator_client: APIClient, pattern: PatternModel
) -> None:
    response = operator_client.get(f"/api/patterns/{pattern.pk}/")
    assert response.status_code == 200
    assert response.data["draft"] == pattern.draft
    assert response.data["latest_version"] is None
    assert response.data["created_by"] == "erik-engineer"


def test_the_list_shows_the_latest_published_version(
    operator_client: APIClient, pattern: PatternModel, engineer: User
) -> None:
    for _ in range(2):
        services.publish_pattern(pattern, published_by=engineer)
    assert operator_client.get("/api/patterns/").data["results"][0]["latest_version"] == 2


def test_a_user_without_membership_sees_an_empty_list(
    loner_client: APIClient, pattern: PatternModel
) -> None:
    response = loner_client.get("/api/patterns/")
    assert response.status_code == 200
    assert response.data["count"] == 0


@pytest.mark.parametrize("pk", ["abc", "99999999999999999999999", "-1"])
def test_a_malformed_or_huge_id_is_not_found(engineer_client: APIClient, pk: str) -> None:
    assert engineer_client.get(f"/api/patterns/{pk}/").status_code == 404


# Creating and editing ------------------------------------------------------------------------


def test_an_engineer_creates_a_pattern_in_their_organisation(
    engineer_client: APIClient, organisation: Organisation
) -> None:
    body = {"name": "Screwing", "description": "cell 4", "draft": factories.valid_document()}
    response = _post_json(engineer_client, "/api/patterns/", body)
    assert response.status_code == 201, response.data
    pattern = PatternModel.objects.get(pk=response.data["id"])
    assert (pattern.organisation, pattern.name, pattern.draft) == (
        organisation,
        "Screwing",
        factories.valid_document(),
    )
    assert pattern.created_by is not None
    assert pattern.created_by.username == "erik-engineer"


def test_a_pattern_created_without_a_draft_gets_an_empty_net(
    admin_client: APIClient,
) -> None:
    response = _post_json(admin_client, "/api/patterns/", {"name": "Blank"})
    assert response.status_code == 201
    assert read_pattern(response.data["draft"]).processes[0].id == "N"


def test_an_operator_may_not_create_a_pattern(
    operator_client: APIClient, organisation: Organisation
) -> None:
    response = _post_json(operator_client, "/api/patterns/", {"name": "Mine"})
    assert response.status_code == 403
    assert not PatternModel.objects.exists()


def test_an_outsider_cannot_create_a_pattern_in_our_organisation(
    outsider_client: APIClient, organisation: Organisation
) -> None:
    body = {"name": "Planted", "organisation": organisation.pk}
    response = _post_json(outsider_client, "/api/patterns/", body)
    assert response.status_code == 400
    assert not organisation.patterns.exists()


def test_a_member_of_two_organisations_must_say_which(
    engineer_client: APIClient, engineer: User, other_organisation: Organisation
) -> None:
    from hrc.organisations import services as organisation_services

    organisation_services.add_member(other_organisation, engineer, "engineer")
    response = _post_json(engineer_client, "/api/patterns/", {"name": "Where?"})
    assert response.status_code == 400
    assert "organisation" in response.data["fields"]
    body = {"name": "There", "organisation": other_organisation.pk}
    assert _post_json(engineer_client, "/api/patterns/", body).status_code == 201


def test_an_engineer_saves_a_draft_that_breaks_the_rules(
    engineer_client: APIClient, pattern: PatternModel
) -> None:
    draft = factories.document_with_duplicate_ids()
    response = engineer_client.patch(
        f"/api/patterns/{pattern.pk}/", {"draft": draft}, format="json"
    )
    assert response.status_code == 200
    pattern.refresh_from_db()
    assert pattern.draft == draft


def test_an_operator_may_not_edit_or_delete_a_pattern(
    operator_client: APIClient, pattern: PatternModel
) -> None:
    url = f"/api/patterns/{pattern.pk}/"
    assert operator_client.patch(url, {"name": "Hijacked"}, format="json").status_code == 403
    assert operator_client.put(url, {"name": "Hijacked"}, format="json").status_code == 403
    assert operator_client.delete(url).status_code == 403
    pattern.refresh_from_db()
    assert pattern.name == "Hand-over"


def test_a_pattern_cannot_move_to_another_organisation(
    engineer_client: APIClient,
    engineer: User,
    pattern: PatternModel,
    other_organisation: Organisation,
) -> None:
    from hrc.organisations import services as organisation_services

    organisation_services.add_member(other_organisation, engineer, "engineer")
    url = f"/api/patterns/{pattern.pk}/"
    response = engineer_client.patch(url, {"organisation": other_organisation.pk}, format="json")
    assert response.status_code == 400
    pattern.refresh_from_db()
    assert pattern.organisation_id != other_organisation.pk


def test_an_engineer_deletes_an_unpublished_pattern(
    engineer_client: APIClient, pattern: PatternModel
) -> None:
    assert engineer_client.delete(f"/api/patterns/{pattern.pk}/").status_code == 204
    assert not PatternModel.objects.exists()


def test_a_published_pattern_is_kept_with_a_409(
    engineer_client: APIClient, pattern: PatternModel, engineer: User
) -> None:
    services.publish_pattern(pattern, published_by=engineer)
    response = engineer_client.delete(f"/api/patterns/{pattern.pk}/")
    assert response.status_code == 409
    assert "published versions" in response.data["detail"]
    assert PatternModel.objects.filter(pk=pattern.pk).exists()


# Bad documents ------------------------------------------------------------------------------


def test_a_body_that_is_not_json_is_a_400(engineer_client: APIClient) -> None:
    response = engineer_client.post(
        "/api/patterns/", b'{"name": "x", "draft": {', content_type="application/json"
    )
    assert response.status_code == 400
    assert response.data["detail"].startswith("JSON parse error")


@pytest.mark.parametrize(
    ("draft", "where"),
    [
        ({"format": "hrc-pattern/2", "processes": []}, "format"),
        ({"format": "hrc-pattern/1", "processes": "N"}, "processes must be a list"),
        ([1, 2, 3], "must be a JSON object"),
        ("hrc-pattern/1", "must be a JSON object"),
    ],
)
def test_a_draft_of_the_wrong_shape_is_a_400_listing_the_issues(
    engineer_client: APIClient, draft: Any, where: str
) -> None:
    response = _post_json(engineer_client, "/api/patterns/", {"name": "Bad", "draft": draft})
    assert response.status_code == 400
    assert response.data["errors"], response.data
    assert all(issue["code"] == "format" for issue in response.data["errors"])
    assert where in response.data["detail"]
    assert not PatternModel.objects.exists()


def test_an_update_with_a_draft_of_the_wrong_shape_changes_nothing(
    engineer_client: APIClient, pattern: PatternModel
) -> None:
    url = f"/api/patterns/{pattern.pk}/"
    response = engineer_client.patch(url, {"name": "New", "draft": {"x": 1}}, format="json")
    assert response.status_code == 400
    pattern.refresh_from_db()
    assert (pattern.name, pattern.draft) == ("Hand-over", factories.valid_document())


@pytest.mark.parametrize("body", [[], "text", 42, None])
def test_a_body_that_is_not_an_object_is_a_400(engineer_client: APIClient, body: Any) -> None:
    assert _post_json(engineer_client, "/api/patterns/", body).status_code == 400


def test_a_10_mb_body_is_refused_with_413(engineer_client: APIClient) -> None:
    body = json.dumps({"name": "big", "description": "x" * (10 * MB)})
    response = engineer_client.post("/api/patterns/", body, content_type="application/json")
    assert response.status_code == 413
    assert not PatternModel.objects.exists()


@pytest.mark.parametrize(
    "raw",
    [
        b'{"name": "deep", "draft": ' + b"[" * 100_000 + b"]" * 100_000 + b"}",
        b'{"name": "deep", "draft": ' + b"[" * 70 + b"]" * 70 + b"}",
        b'{"name": "nul\\u0000", "draft": {}}',
        b'{"name": "nan", "description": NaN}',
        b'{"name": "inf", "draft": {"format": "hrc-pattern/1", "x": 1e400}}',
        b'{"name": "\xff\xfe"}',
    ],
    ids=["very-deep", "deeper-than-64", "nul", "nan", "overflow", "not-utf8"],
)
def test_json_the_database_cannot_hold_is_a_400(engineer_client: APIClient, raw: bytes) -> None:
    response = engineer_client.post("/api/patterns/", raw, content_type="application/json")
    assert response.status_code == 400
    assert not PatternModel.objects.exists()


def test_a_body_in_another_media_type_is_a_415(engineer_client: APIClient) -> None:
    response = engineer_client.post("/api/patterns/", "name=x", content_type="text/plain")
    assert response.status_code == 415


# Check and publish --------------------------------------------------------------------------


def test_check_reports_a_valid_sound_pattern(
    engineer_client: APIClient, pattern: PatternModel
) -> None:
    response = engineer_client.post(f"/api/patterns/{pattern.pk}/check/")
    assert response.status_code == 200
    assert response.data["valid"] is True
    assert response.data["sound"] is True
    assert response.data["patterns"] == ["synchronized"]
    assert response.data["errors"] == []


def test_colliding_ids_save_then_check_reports_and_publish_refuses(
    engineer_client: APIClient, organisation: Organisation
) -> None:
    body = {"name": "Colliding", "draft": factories.document_with_duplicate_ids()}
    created = _post_json(engineer_client, "/api/patterns/", body)
    assert created.status_code == 201
    pk = created.data["id"]

    check = engineer_client.post(f"/api/patterns/{pk}/check/")
    assert check.status_code == 200
    assert check.data["valid"] is False
    duplicate = [e for e in check.data["errors"] if e["code"] == "duplicate-id"]
    assert duplicate
    assert "p2" in duplicate[0]["elements"]

    publish = engineer_client.post(f"/api/patterns/{pk}/publish/")
    assert publish.status_code == 400
    assert publish.data["report"]["valid"] is False
    assert "duplicate-id" in {e["code"] for e in publish.data["report"]["errors"]}
    assert not PatternVersion.objects.exists()


def test_an_unsound_draft_is_refused_with_the_witness(
    engineer_client: APIClient, organisation: Organisation
) -> None:
    pattern = factories.make_pattern(organisation, draft=factories.unsound_document())
    response = engineer_client.post(f"/api/patterns/{pattern.pk}/publish/")
    assert response.status_code == 400
    report = response.data["report"]
    assert report["sound"] is False  # a real boolean, not the string "False"
    assert {e["code"] for e in report["errors"]} == {"unsound"}


def test_an_engineer_publishes_versions_1_and_2(
    engineer_client: APIClient, pattern: PatternModel
) -> None:
    first = engineer_client.post(f"/api/patterns/{pattern.pk}/publish/")
    second = engineer_client.post(f"/api/patterns/{pattern.pk}/publish/")
    assert (first.status_code, second.status_code) == (201, 201)
    assert (first.data["number"], second.data["number"]) == (1, 2)
    assert first.data["document"] == pattern.draft
    assert first.data["report"]["valid"] is True
    assert first.data["published_by"] == "erik-engineer"


# Versions -----------------------------------------------------------------------------------


@pytest.fixture
def published(pattern: PatternModel, engineer: User) -> list[PatternVersion]:
    return [services.publish_pattern(pattern, published_by=engineer) for _ in range(2)]


def test_the_versions_of_a_pattern_newest_first(
    operator_client: APIClient, pattern: PatternModel, published: list[PatternVersion]
) -> None:
    response = operator_client.get(f"/api/patterns/{pattern.pk}/versions/")
    assert response.status_code == 200
    assert [v["number"] for v in response.data["results"]] == [2, 1]


def test_a_version_is_read_with_its_document_and_report(
    operator_client: APIClient, published: list[PatternVersion]
) -> None:
    response = operator_client.get(f"/api/pattern-versions/{published[0].pk}/")
    assert response.status_code == 200
    assert response.data["number"] == 1
    assert response.data["document"]["format"] == "hrc-pattern/1"
    assert response.data["report"]["sound"] is True


def test_versions_can_be_filtered_by_pattern(
    operator_client: APIClient,
    organisation: Organisation,
    engineer: User,
    published: list[PatternVersion],
) -> None:
    other = factories.make_pattern(organisation)
    services.publish_pattern(other, published_by=engineer)
    response = operator_client.get(f"/api/pattern-versions/?pattern={other.pk}")
    assert [v["pattern"] for v in response.data["results"]] == [other.pk]
    assert operator_client.get("/api/pattern-versions/?pattern=abc").status_code == 400


@pytest.mark.parametrize("method", ["put", "patch", "delete"])
def test_a_version_cannot_be_changed_or_deleted(
    admin_client: APIClient, published: list[PatternVersion], method: str
) -> None:
    url = f"/api/pattern-versions/{published[0].pk}/"
    response = getattr(admin_client, method)(url, {"number": 7}, format="json")
    assert response.status_code == 405
    published[0].refresh_from_db()
    assert published[0].number == 1


# Import and export --------------------------------------------------------------------------


def test_importing_json_creates_a_pattern_named_after_the_document(
    engineer_client: APIClient, organisation: Organisation
) -> None:
    response = _post_json(engineer_client, "/api/patterns/import/", factories.valid_document())
    assert response.status_code == 201, response.data
    pattern = PatternModel.objects.get(pk=response.data["id"])
    assert pattern.name == "Hand-over (1 operator, 1 cobot)"
    assert pattern.draft == factories.valid_document()
    assert pattern.organisation == organisation


def test_import_may_bring_a_draft_that_breaks_the_rules(engineer_client: APIClient) -> None:
    document = factories.document_with_duplicate_ids()
    response = _post_json(engineer_client, "/api/patterns/import/", document)
    assert response.status_code == 201


@pytest.mark.parametrize(
    ("body", "content_type"),
    [
        (b"{not json", "application/json"),
        (b'{"format": "hrc-pattern/1", "processes": {}}', "application/json"),
        (b"[]", "application/json"),
        (b"<pnml><net", "application/xml"),
        (b"just text", "text/xml"),
    ],
)
def test_an_unreadable_import_is_a_400(
    engineer_client: APIClient, body: bytes, content_type: str
) -> None:
    response = engineer_client.post("/api/patterns/import/", body, content_type=content_type)
    assert response.status_code == 400
    assert response.data["detail"]
    assert not PatternModel.objects.exists()


@pytest.mark.parametrize("content_type", ["application/xml", "text/xml", "application/json"])
def test_a_signed_in_browser_imports_with_its_csrf_token(engineer: User, content_type: str) -> None:
    # A session user goes through DRF's CSRF check, which reads the body before the view.
    browser = Client(enforce_csrf_checks=True)
    browser.force_login(engineer)
    browser.get("/accounts/login/")  # sets the csrftoken cookie
    token = browser.cookies["csrftoken"].value
    body = (
        json.dumps(factories.valid_document()).encode()
        if content_type == "application/json"
        else pattern_to_pnml(read_pattern(factories.valid_document())).encode()
    )

    response = browser.post(
        "/api/patterns/import/", body, content_type=content_type, HTTP_X_CSRFTOKEN=token
    )

    assert response.status_code == 201, response.content
    assert PatternModel.objects.count() == 1


def test_a_10_mb_import_is_refused_with_413(engineer_client: APIClient) -> None:
    body = b"<pnml>" + b" " * (10 * MB) + b"</pnml>"
    response = engineer_client.post("/api/patterns/import/", body, content_type="application/xml")
    assert response.status_code == 413


def test_an_operator_may_not_import(operator_client: APIClient) -> None:
    response = _post_json(operator_client, "/api/patterns/import/", factories.valid_document())
    assert response.status_code == 403
    assert not PatternModel.objects.exists()


def test_an_outsider_cannot_import_into_our_organisation(
    outsider_client: APIClient, organisation: Organisation
) -> None:
    url = f"/api/patterns/import/?organisation={organisation.pk}"
    response = _post_json(outsider_client, url, factories.valid_document())
    assert response.status_code == 400
    assert not organisation.patterns.exists()


def test_export_gives_the_draft_as_a_json_file(
    operator_client: APIClient, pattern: PatternModel
) -> None:
    response = operator_client.get(f"/api/patterns/{pattern.pk}/export/")
    assert response.status_code == 200
    assert response["Content-Type"].startswith("application/json")
    assert response["Content-Disposition"] == 'attachment; filename="hand-over.json"'
    assert json.loads(response.content) == pattern.draft


@pytest.mark.parametrize(
    "content_type", ["application/xml", "text/xml", "application/octet-stream"]
)
def test_pnml_round_trips_through_export_and_import(
    engineer_client: APIClient, pattern: PatternModel, content_type: str
) -> None:
    exported = engineer_client.get(f"/api/patterns/{pattern.pk}/export/?format=pnml")
    assert exported.status_code == 200
    assert exported["Content-Type"].startswith("application/xml")
    assert exported.content.startswith(b"<?xml")
    url = "/api/patterns/import/"
    if content_type == "application/octet-stream":
        url += "?format=pnml"  # the format says PNML when the content type does not
    imported = engineer_client.post(url, exported.content, content_type=content_type)
    assert imported.status_code == 201, imported.data
    assert read_pattern(imported.data["draft"]) == read_pattern(pattern.draft)


def test_a_published_version_exports_under_its_number(
    operator_client: APIClient, published: list[PatternVersion]
) -> None:
    response = operator_client.get(f"/api/pattern-versions/{published[1].pk}/export/?format=json")
    assert response.status_code == 200
    assert response["Content-Disposition"] == 'attachment; filename="hand-over-v2.json"'
    pnml = operator_client.get(f"/api/pattern-versions/{published[1].pk}/export/?format=pnml")
    assert pnml.status_code == 200
    assert b"<pnml" in pnml.content


def test_an_unknown_format_is_a_400_naming_the_formats(
    engineer_client: APIClient, pattern: PatternModel
) -> None:
    exported = engineer_client.get(f"/api/patterns/{pattern.pk}/export/?format=yaml")
    assert exported.status_code == 400
    assert "json, pnml or bpmn" in exported.json()["detail"]
    imported = _post_json(engineer_client, "/api/patterns/import/?format=yaml", {})
    assert imported.status_code == 400
    assert "json, pnml or bpmn" in imported.data["detail"]


@pytest.mark.parametrize(
    "xml", [BILLION_LAUGHS.encode(), EXTERNAL_ENTITY.encode()], ids=["bomb", "external"]
)
def test_hostile_xml_is_refused(engineer_client: APIClient, xml: bytes) -> None:
    response = engineer_client.post("/api/patterns/import/", xml, content_type="application/xml")
    assert response.status_code == 400
    assert "DTD" in response.data["detail"] or "entity" in response.data["detail"]
    assert not PatternModel.objects.exists()
