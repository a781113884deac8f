"""Running a version from the browser and the API: its page, the start form, start rights, steering.

The version page sets the default mapping, who may start it and whether it
is in service; the start form starts N cases alike or none; a refusal shows
at its field and writes nothing. Operators start only at one of the
version's cells, with its defaults; outsiders see nothing.
"""

from typing import Any

import pytest
from django.contrib.auth.models import User
from django.test import Client
from rest_framework.test import APIClient

from hrc.cases import services
from hrc.cases.choices import CaseStatus
from hrc.cases.models import Case
from hrc.cobots.models import Cobot
from hrc.errors import Invalid
from hrc.organisations import services as organisation_services
from hrc.organisations.models import Organisation
from hrc.patterns.models import PatternVersion
from hrc.patterns.services import retire_version, set_start_rights
from tests import factories

pytestmark = pytest.mark.django_db


def _client(user: User) -> Client:
    client = Client()
    client.force_login(user)
    return client


@pytest.fixture
def version(organisation: Organisation, engineer: User) -> PatternVersion:
    """The hand-over pattern with start data: a whole number, a yes/no, a list."""
    document = factories.valid_document()
    document["data"] = {"batch": 1, "urgent": False, "spots": [1, 2]}
    return factories.make_version(organisation, published_by=engineer, draft=document)


def _start_form(operator: User, cobot: Cobot, **changes: Any) -> dict[str, Any]:
    form = {
        "actor__o": f"users:{operator.pk}",
        "actor__c": f"cobot:{cobot.pk}",
        "data__batch": "1",
        "data__urgent": "no",
        "data__spots": "[1, 2]",
        "reference": "ORDER-7",
        "count": "1",
    }
    return {**form, **changes}


# The start form ----------------------------------------------------------------------------


def test_the_start_form_offers_the_defaults_and_starts_two_cases_alike(
    engineer: User, operator: User, cobot: Cobot, version: PatternVersion
) -> None:
    services.set_default_actor_mapping(
        version, {"o": {"users": [operator.pk]}, "c": {"cobot": cobot.pk}}
    )
    client = _client(engineer)
    page = client.get(f"/cases/new/?version={version.pk}")
    assert page.status_code == 200
    html = page.content.decode()
    assert f'<option value="users:{operator.pk}" selected>' in html
    assert f'<option value="cobot:{cobot.pk}" selected>' in html
    # A yes/no is two answers with "Choose…", the default answered.
    assert '<option value="no" selected>No</option>' in html

    response = client.post(
        f"/cases/new/?version={version.pk}",
        _start_form(operator, cobot, data__batch="4", count="2"),
    )
    assert response.status_code == 302
    assert response["Location"] == f"/cases/?version={version.pk}"
    cases = list(Case.objects.filter(version=version))
    assert len(cases) == 2
    for case in cases:
        assert case.reference == "ORDER-7"
        assert case.data["batch"] == 4
        assert case.data["urgent"] is False
        assert case.started_by == engineer


def test_one_case_opens_its_page(
    engineer: User, operator: User, cobot: Cobot, version: PatternVersion
) -> None:
    response = _client(engineer).post(
        f"/cases/new/?version={version.pk}", _start_form(operator, cobot)
    )
    case = Case.objects.get()
    assert response["Location"] == f"/cases/{case.pk}/"


@pytest.mark.parametrize(
    ("changes", "field", "message"),
    [
        ({"data__batch": "many"}, "data__batch", "Enter a whole number."),
        ({"data__spots": "{"}, "data__spots", "This is not JSON"),
        ({"data__spots": '{"a": 1}'}, "data__spots", "Give a list, as the default is"),
        ({"data__urgent": ""}, "data__urgent", "This field is required."),
        ({"count": "51"}, "count", "less than or equal to 50"),
        ({"actor__c": ""}, "actor__c", "This field is required."),
    ],
)
def test_bad_input_is_shown_at_its_field_and_starts_nothing(
    engineer: User,
    operator: User,
    cobot: Cobot,
    version: PatternVersion,
    changes: dict[str, str],
    field: str,
    message: str,
) -> None:
    response = _client(engineer).post(
        f"/cases/new/?version={version.pk}", _start_form(operator, cobot, **changes)
    )
    assert response.status_code == 400
    assert message in str(response.context["form"].errors[field])
    assert not Case.objects.exists()


def test_another_organisations_cobot_or_a_deactivated_person_starts_nothing(
    engineer: User,
    operator: User,
    cobot: Cobot,
    version: PatternVersion,
    other_organisation: Organisation,
) -> None:
    foreign = factories.make_cobot(other_organisation, name="theirs")
    client = _client(engineer)
    response = client.post(
        f"/cases/new/?version={version.pk}",
        _start_form(operator, cobot, actor__c=f"cobot:{foreign.pk}"),
    )
    assert response.status_code == 400
    assert "Select a valid choice" in str(response.context["form"].errors["actor__c"])

    # Chosen while active, deactivated before the start: the service refuses at the field.
    operator.is_active = False
    operator.save()
    with pytest.raises(Invalid) as refused:
        services.start_cases(
            version,
            started_by=engineer,
            actor_mapping={"o": {"users": [operator.pk]}, "c": {"cobot": cobot.pk}},
        )
    assert list(refused.value.fields) == ["actor_mapping.o"]
    assert not Case.objects.exists()


def test_data_of_the_wrong_type_is_refused_by_the_service_at_its_key(
    engineer: User, operator: User, cobot: Cobot, version: PatternVersion
) -> None:
    mapping = {"o": {"users": [operator.pk]}, "c": {"cobot": cobot.pk}}
    with pytest.raises(Invalid) as refused:
        services.start_cases(
            version, started_by=engineer, actor_mapping=mapping, data={"urgent": "yes"}
        )
    assert list(refused.value.fields) == ["data.urgent"]
    assert "urgent must be yes or no" in str(refused.value)
    assert not Case.objects.exists()


def test_a_retired_version_starts_nothing_and_running_cases_go_on(
    engineer: User, operator: User, cobot: Cobot, version: PatternVersion
) -> None:
    mapping = {"o": {"users": [operator.pk]}, "c": {"cobot": cobot.pk}}
    running = services.start_case(version, started_by=engineer, actor_mapping=mapping)
    retire_version(version, retired=True)
    page = _client(engineer).get(f"/cases/new/?version={version.pk}")
    assert "is retired: it starts no new cases" in page.content.decode()
    response = _client(engineer).post(
        f"/cases/new/?version={version.pk}", _start_form(operator, cobot)
    )
    assert response.status_code == 400
    assert Case.objects.count() == 1
    running.refresh_from_db()
    assert running.status == CaseStatus.RUNNING


# The version page --------------------------------------------------------------------------


def test_the_version_page_saves_the_mapping_rights_and_retiring(
    engineer: User,
    operator: User,
    cobot: Cobot,
    version: PatternVersion,
    organisation: Organisation,
) -> None:
    organisation_services.ensure_cell(organisation, "cell-a")
    client = _client(engineer)
    page = client.get(f"/patterns/versions/{version.pk}/")
    assert page.status_code == 200
    assert "Synchronized" in page.content.decode()

    saved = client.post(
        f"/patterns/versions/{version.pk}/",
        {
            "form": "mapping",
            "mapping-actor__o": f"users:{operator.pk}",
            "mapping-actor__c": f"cobot:{cobot.pk}",
        },
    )
    assert saved.status_code == 302
    version.refresh_from_db()
    assert version.default_actor_mapping == {
        "o": {"users": [operator.pk]},
        "c": {"cobot": cobot.pk},
    }

    client.post(
        f"/patterns/versions/{version.pk}/",
        {"form": "rights", "rights-roles": ["engineer", "operator"], "rights-cells": ["cell-a"]},
    )
    client.post(f"/patterns/versions/{version.pk}/", {"form": "retire"})
    version.refresh_from_db()
    assert version.start_roles == ["engineer", "operator"]
    assert version.start_cells == ["cell-a"]
    assert version.retired_at is not None


def test_a_cell_the_organisation_does_not_have_is_refused_at_the_field(
    engineer: User, version: PatternVersion
) -> None:
    response = _client(engineer).post(
        f"/patterns/versions/{version.pk}/",
        {"form": "rights", "rights-roles": ["engineer"], "rights-cells": ["nowhere"]},
    )
    assert response.status_code == 400
    assert "nowhere" in str(response.context["rights_form"].errors["cells"])
    version.refresh_from_db()
    assert version.start_cells == []


@pytest.mark.parametrize("url", ["/patterns/versions/{v}/", "/cases/new/?version={v}"])
def test_an_outsider_gets_404_and_an_operator_403(
    url: str, outsider: User, operator: User, version: PatternVersion
) -> None:
    assert _client(outsider).get(url.format(v=version.pk)).status_code == 404
    assert _client(outsider).post(url.format(v=version.pk), {"form": "retire"}).status_code == 404
    assert _client(operator).get(url.format(v=version.pk)).status_code == 403
    version.refresh_from_db()
    assert version.retired_at is None


def test_the_chooser_lists_only_our_versions_in_service(
    engineer: User, outsider: User, version: PatternVersion, other_organisation: Organisation
) -> None:
    theirs = factories.make_version(other_organisation, published_by=outsider)
    html = _client(engineer).get("/cases/new/").content.decode()
    assert f"?version={version.pk}" in html
    assert f"?version={theirs.pk}" not in html
    retire_version(version, retired=True)
    assert f"?version={version.pk}" not in _client(engineer).get("/cases/new/").content.decode()


# Steering a case from its page -------------------------------------------------------------


def test_a_case_is_suspended_resumed_and_cancelled_from_its_page(
    engineer: User, choice_case: Case
) -> None:
    client = _client(engineer)
    url = f"/cases/{choice_case.pk}/control/"
    assert client.post(url, {"action": "suspend"}).status_code == 302
    choice_case.refresh_from_db()
    assert choice_case.status == CaseStatus.SUSPENDED
    client.post(url, {"action": "resume"})
    refused = client.post(url, {"action": "cancel"})
    assert refused.status_code == 400
    choice_case.refresh_from_db()
    assert choice_case.status == CaseStatus.RUNNING
    client.post(url, {"action": "cancel", "confirm": "yes"})
    choice_case.refresh_from_db()
    assert choice_case.status == CaseStatus.CANCELLED
    assert client.post(url, {"action": "resume"}).status_code == 409


def test_an_outsider_cannot_steer_our_case(
    outsider: User, operator: User, choice_case: Case
) -> None:
    url = f"/cases/{choice_case.pk}/control/"
    assert _client(outsider).post(url, {"action": "suspend"}).status_code == 404
    assert _client(operator).post(url, {"action": "suspend"}).status_code == 403
    choice_case.refresh_from_db()
    assert choice_case.status == CaseStatus.RUNNING


# Operators at their cell, over the API -----------------------------------------------------


def test_an_operator_starts_at_a_start_cell_with_the_defaults_only(
    engineer: User,
    operator: User,
    cobot: Cobot,
    version: PatternVersion,
    organisation: Organisation,
) -> None:
    organisation_services.ensure_cell(organisation, "cell-a")
    organisation_services.ensure_cell(organisation, "cell-b")
    services.set_default_actor_mapping(
        version, {"o": {"users": [operator.pk]}, "c": {"cobot": cobot.pk}}
    )
    client = APIClient()
    client.force_authenticate(operator)
    body = {"version": version.pk, "cell": "cell-a", "reference": "W-1", "data": {"batch": 3}}
    assert client.post("/api/cases/", body, format="json").status_code == 403
    assert client.get("/api/pattern-versions/?startable_at=cell-a").json() == []

    set_start_rights(version, roles=["engineer", "operator"], cells=["cell-a"])
    listed = client.get("/api/pattern-versions/?startable_at=cell-a").json()
    assert [v["id"] for v in listed] == [version.pk]
    assert listed[0]["start_form"]["properties"]["batch"] == {
        "title": "batch",
        "default": 1,
        "type": "integer",
    }
    assert client.get("/api/pattern-versions/?startable_at=cell-b").json() == []
    elsewhere = client.post("/api/cases/", {**body, "cell": "cell-b"}, format="json")
    assert elsewhere.status_code == 403
    assert "at the tablet of its cells (cell-a)" in elsewhere.json()["detail"]
    mapped = {**body, "actor_mapping": {"c": {"cobot": cobot.pk}}}
    assert client.post("/api/cases/", mapped, format="json").status_code == 403
    assert not Case.objects.exists()

    started = client.post("/api/cases/", body, format="json")
    assert started.status_code == 201, started.json()
    case = Case.objects.get()
    assert (case.reference, case.data["batch"], case.started_by) == ("W-1", 3, operator)


def test_an_outsider_sees_no_startable_version_and_cannot_set_rights(
    outsider: User, version: PatternVersion, organisation: Organisation
) -> None:
    organisation_services.ensure_cell(organisation, "cell-a")
    set_start_rights(version, roles=["operator"], cells=["cell-a"])
    client = APIClient()
    client.force_authenticate(outsider)
    assert client.get("/api/pattern-versions/?startable_at=cell-a").json() == []
    body = {"roles": ["engineer"], "cells": []}
    assert (
        client.put(
            f"/api/pattern-versions/{version.pk}/start-rights/", body, format="json"
        ).status_code
        == 404
    )
    assert (
        client.post(
            f"/api/pattern-versions/{version.pk}/retire/", {"on": True}, format="json"
        ).status_code
        == 404
    )
    version.refresh_from_db()
    assert (version.start_roles, version.retired_at) == (["operator"], None)


def test_engineers_set_rights_retire_and_archive_over_the_api(
    engineer: User, operator: User, version: PatternVersion
) -> None:
    client = APIClient()
    client.force_authenticate(engineer)
    bad = client.put(
        f"/api/pattern-versions/{version.pk}/start-rights/", {"roles": ["boss"]}, format="json"
    )
    assert bad.status_code == 400
    assert "No such role: boss" in str(bad.json())
    assert (
        client.post(
            f"/api/pattern-versions/{version.pk}/retire/", {"on": True}, format="json"
        ).status_code
        == 200
    )
    listed = client.get("/api/pattern-versions/").json()["results"]
    assert listed[0]["pattern_name"] == version.pattern.name
    assert listed[0]["pattern_class"] == ["synchronized"]
    assert listed[0]["retired_at"] is not None
    archived = client.post(
        f"/api/patterns/{version.pattern_id}/archive/", {"on": True}, format="json"
    )
    assert archived.json()["archived_at"] is not None

    operators = APIClient()
    operators.force_authenticate(operator)
    assert (
        operators.post(
            f"/api/pattern-versions/{version.pk}/retire/", {"on": False}, format="json"
        ).status_code
        == 403
    )
