"""A pattern's `data`: what every case's data starts with, a case's own data laid over it."""

import pytest
from django.contrib.auth.models import User
from rest_framework.test import APIClient

from hrc.cases.models import Case
from hrc.organisations.models import Organisation
from hrc.patterns import services as pattern_services
from tests import factories


@pytest.mark.django_db
def test_a_case_starts_with_the_patterns_data_and_its_own_data_wins_per_key(
    organisation: Organisation, engineer: User, operator: User, engineer_client: APIClient
) -> None:
    document = factories.choice_document()
    document["data"] = {"tray": 1, "spots": ["left", "right"], "checked": []}
    version = factories.make_version(organisation, published_by=engineer, draft=document)
    mapping = {"o": {"users": [operator.pk]}}

    plain = factories.make_case(version, started_by=engineer, actor_mapping=mapping)
    response = engineer_client.post(
        "/api/cases/",
        {"version": version.pk, "actor_mapping": mapping, "data": {"tray": 7, "urgent": True}},
        format="json",
    )

    assert plain.data == {"tray": 1, "spots": ["left", "right"], "checked": []}
    assert response.status_code == 201, response.data
    started = Case.objects.get(pk=response.data["id"])
    assert started.data == {"tray": 7, "spots": ["left", "right"], "checked": [], "urgent": True}
    assert response.data["data"] == started.data


@pytest.mark.django_db
def test_a_pattern_whose_data_is_no_object_is_not_published(
    organisation: Organisation, engineer: User
) -> None:
    document = factories.choice_document()
    document["data"] = ["tray", 1]
    pattern = factories.make_pattern(organisation, draft=document, created_by=engineer)

    with pytest.raises(pattern_services.PublishRefused) as refused:
        pattern_services.publish_pattern(pattern, published_by=engineer)
    assert "'data'" in str(refused.value.report["errors"])
