"""Checks bounded per request and per organisation (issue 17, finding 5).

A 20 KB pattern of parallel lanes has millions of markings: a check of it in a
request answers "too large to decide in N s" within its budget; an
organisation runs at most HRC_ENGINE_SLOTS engine requests at once, the next
gets a 429; and operators reach none of the actions that run the engine.
`settings` is pytest-django's fixture, restored after each test.
"""

import json
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

import pytest
from django.db import connections
from rest_framework.test import APIClient

from hrc.organisations.models import Organisation
from hrc.patterns.checking import engine_slot
from hrc.patterns.models import PatternModel, PatternVersion
from tests import factories
from tests.engine.builders import parallel_lanes


def _post(client: APIClient, url: str, body: Any = None) -> Any:
    if body is None:
        return client.post(url)
    return client.post(url, json.dumps(body), content_type="application/json")


@contextmanager
def _slots_held_elsewhere(organisation_id: int, count: int) -> Iterator[None]:
    """`count` of the organisation's slots, held by other database sessions (other workers)."""
    holding = threading.Barrier(count + 1)
    done = threading.Event()

    def hold() -> None:
        try:
            with engine_slot(organisation_id):
                holding.wait(timeout=10)
                done.wait(timeout=30)
        finally:
            connections.close_all()

    threads = [threading.Thread(target=hold) for _ in range(count)]
    for thread in threads:
        thread.start()
    holding.wait(timeout=10)
    try:
        yield
    finally:
        done.set()
        for thread in threads:
            thread.join(timeout=30)


# Operators ------------------------------------------------------------------------------------


def _engine_requests(pattern: PatternModel) -> list[tuple[str, Any]]:
    document = factories.valid_document()
    return [
        (f"/api/patterns/{pattern.pk}/check/", None),
        (f"/api/patterns/{pattern.pk}/publish/", None),
        ("/api/patterns/check-document/", document),
        ("/api/patterns/layout/", document),
        ("/api/patterns/execution-net/", document),
        ("/api/patterns/import/", document),
    ]


def test_operators_may_trigger_no_check_layout_import_or_publish(
    operator_client: APIClient, pattern: PatternModel
) -> None:
    for url, body in _engine_requests(pattern):
        response = _post(operator_client, url, body)

        assert response.status_code == 403, url
        assert "Only engineers and admins" in response.data["detail"], url
    assert not PatternVersion.objects.exists()
    assert PatternModel.objects.count() == 1


# The budget of a check in a request ------------------------------------------------------------


def test_the_huge_patterns_check_answers_too_large_to_decide_within_its_budget(
    engineer_client: APIClient, organisation: Organisation, settings: Any
) -> None:
    settings.HRC_CHECK_SECONDS = 0.25
    huge = parallel_lanes(10, 8)
    stored = factories.make_pattern(organisation, draft=huge)

    for response in (
        _post(engineer_client, "/api/patterns/check-document/", huge),
        _post(engineer_client, f"/api/patterns/{stored.pk}/check/"),
    ):
        assert response.status_code == 200
        assert response.data["sound"] is None
        assert response.data["errors"] == []
        (too_large,) = [
            w for w in response.data["warnings"] if w["code"] == "state-space-too-large"
        ]
        assert "too large to decide in 0.25 s" in too_large["message"]
        assert response.data["stats"]["markings"] < settings.HRC_CHECK_MARKINGS


# Per organisation ------------------------------------------------------------------------------


@pytest.mark.django_db(transaction=True)
def test_a_check_over_the_organisations_limit_is_refused_with_429_until_a_slot_frees(
    engineer_client: APIClient,
    outsider_client: APIClient,
    organisation: Organisation,
    settings: Any,
) -> None:
    settings.HRC_ENGINE_SLOTS = 2
    pattern = factories.make_pattern(organisation)
    document = factories.valid_document()

    with _slots_held_elsewhere(organisation.pk, 2):
        refused = [
            _post(engineer_client, f"/api/patterns/{pattern.pk}/check/"),
            _post(engineer_client, "/api/patterns/check-document/", document),
            _post(engineer_client, "/api/patterns/layout/", document),
            _post(engineer_client, f"/api/patterns/{pattern.pk}/publish/"),
        ]
        elsewhere = _post(outsider_client, "/api/patterns/check-document/", document)

    for response in refused:
        assert response.status_code == 429
        assert "already runs 2 checks" in response.data["detail"]
        assert int(response["Retry-After"]) >= 1
    assert not PatternVersion.objects.exists()
    assert elsewhere.status_code == 200  # another organisation's slots are its own
    assert _post(engineer_client, f"/api/patterns/{pattern.pk}/check/").status_code == 200


@pytest.mark.django_db(transaction=True)
def test_below_the_limit_a_check_runs_beside_one_held_elsewhere(
    engineer_client: APIClient, organisation: Organisation, settings: Any
) -> None:
    settings.HRC_ENGINE_SLOTS = 2
    pattern = factories.make_pattern(organisation)

    with _slots_held_elsewhere(organisation.pk, 1):
        response = _post(engineer_client, f"/api/patterns/{pattern.pk}/check/")

    assert response.status_code == 200
    assert response.data["valid"] is True
