"""/api/members/, /api/teams/, /api/cells/, /api/admin-records/: admins write, members read, the wall holds."""

from __future__ import annotations

import pytest
from django.contrib.auth.models import User
from django.urls import resolve
from rest_framework.test import APIClient

from hrc.live.api.views import StopCellView
from hrc.organisations import services as organisation_services
from hrc.organisations.choices import AdminAction, Role
from hrc.organisations.models import AdminRecord, Cell, Membership, Organisation, Team
from tests.factories import make_cobot, make_member

pytestmark = pytest.mark.django_db


def _client(user: User) -> APIClient:
    client = APIClient()
    client.force_authenticate(user)
    return client


def test_an_admin_adds_a_member_and_reads_the_password_once(
    admin_client: APIClient, organisation: Organisation
) -> None:
    team = Team.objects.create(organisation=organisation, name="Crew")
    response = admin_client.post(
        "/api/members/",
        {
            "organisation": organisation.pk,
            "username": "ada",
            "role": "operator",
            "teams": [team.pk],
        },
        format="json",
    )
    assert response.status_code == 201, response.data
    assert APIClient().login(username="ada", password=response.data["password"])
    assert response.data["teams"] == [team.pk]
    listed = admin_client.get(f"/api/members/{response.data['id']}/").data
    assert "password" not in listed
    assert AdminRecord.objects.filter(action=AdminAction.PERSON_ADDED, target="ada").exists()


def test_bad_member_input_names_the_field_and_writes_nothing(
    admin_client: APIClient,
    organisation: Organisation,
    other_organisation: Organisation,
    operator: User,
) -> None:
    theirs = Team.objects.create(organisation=other_organisation, name="Theirs")
    users = User.objects.count()
    taken = admin_client.post(
        "/api/members/", {"organisation": organisation.pk, "username": operator.username, "role": "operator"}, format="json"
    )  # fmt: skip
    stranger_team = admin_client.post(
        "/api/members/", {"organisation": organisation.pk, "username": "bob", "role": "operator", "teams": [theirs.pk]}, format="json"
    )  # fmt: skip
    their_org = admin_client.post(
        "/api/members/", {"organisation": other_organisation.pk, "username": "bob", "role": "operator"}, format="json"
    )  # fmt: skip
    assert taken.status_code == 400
    assert "username" in str(taken.data)
    assert stranger_team.status_code == 400
    assert "teams" in str(stranger_team.data)
    assert their_org.status_code == 400
    assert "organisation" in str(their_org.data)
    assert User.objects.count() == users
    assert not AdminRecord.objects.exists()


def test_an_admin_changes_a_role_and_teams_resets_a_password_and_deactivates(
    admin_client: APIClient, organisation: Organisation, operator: User
) -> None:
    membership = Membership.objects.get(user=operator)
    team = Team.objects.create(organisation=organisation, name="Crew")
    changed = admin_client.patch(
        f"/api/members/{membership.pk}/", {"role": "engineer", "teams": [team.pk]}, format="json"
    )
    assert changed.status_code == 200
    assert changed.data["role"] == "engineer"
    assert changed.data["teams"] == [team.pk]
    reset = admin_client.post(f"/api/members/{membership.pk}/reset-password/")
    assert APIClient().login(username=operator.username, password=reset.data["password"])
    gone = admin_client.post(f"/api/members/{membership.pk}/deactivate/")
    assert gone.status_code == 200
    assert gone.data["is_active"] is False
    operator.refresh_from_db()
    assert not operator.is_active


def test_the_last_admin_cannot_demote_themselves(admin_client: APIClient, admin: User) -> None:
    membership = Membership.objects.get(user=admin)
    response = admin_client.patch(f"/api/members/{membership.pk}/", {"role": "operator"}, format="json")  # fmt: skip
    assert response.status_code == 400
    assert "last admin" in str(response.data)
    assert admin_client.post(f"/api/members/{membership.pk}/deactivate/").status_code == 400


def test_engineers_and_operators_may_read_but_not_write(
    engineer: User, operator: User, organisation: Organisation
) -> None:
    team = Team.objects.create(organisation=organisation, name="Crew")
    cell = Cell.objects.create(organisation=organisation, name="weld")
    membership = Membership.objects.get(user=operator)
    for user in (engineer, operator):
        client = _client(user)
        assert client.get("/api/teams/").data["count"] == 1
        assert client.post("/api/members/", {"organisation": organisation.pk, "username": "x", "role": "admin"}, format="json").status_code == 403  # fmt: skip
        assert client.post("/api/teams/", {"organisation": organisation.pk, "name": "x"}, format="json").status_code == 403  # fmt: skip
        assert client.post("/api/cells/", {"organisation": organisation.pk, "name": "x"}, format="json").status_code == 403  # fmt: skip
        assert client.patch(f"/api/members/{membership.pk}/", {"role": "admin"}, format="json").status_code == 403  # fmt: skip
        assert client.post(f"/api/members/{membership.pk}/deactivate/").status_code == 403
        assert client.delete(f"/api/teams/{team.pk}/").status_code == 403
        assert client.delete(f"/api/cells/{cell.pk}/").status_code == 403
        assert client.get("/api/admin-records/").data["count"] == 0
    membership.refresh_from_db()
    assert membership.role == Role.OPERATOR
    assert membership.is_active
    assert Team.objects.count() == 1
    assert Cell.objects.count() == 1
    assert not User.objects.filter(username="x").exists()


def test_an_admin_of_another_organisation_sees_and_changes_nothing(
    admin_client: APIClient,
    organisation: Organisation,
    other_organisation: Organisation,
    operator: User,
) -> None:
    admin_client.post(
        "/api/teams/", {"organisation": organisation.pk, "name": "Crew"}, format="json"
    )
    team = Team.objects.get(name="Crew")
    cell = Cell.objects.create(organisation=organisation, name="weld")
    membership = Membership.objects.get(user=operator)
    stranger = _client(make_member(other_organisation, Role.ADMIN))
    for path in ("/api/members/", "/api/teams/", "/api/cells/", "/api/admin-records/"):
        results = stranger.get(path).data["results"]
        assert all(row["organisation"] == other_organisation.pk for row in results), path
    for path in (f"/api/members/{membership.pk}/", f"/api/teams/{team.pk}/", f"/api/cells/{cell.pk}/"):  # fmt: skip
        assert stranger.get(path).status_code == 404
        assert stranger.patch(path, {"role": "admin", "name": "x", "description": "x"}, format="json").status_code == 404  # fmt: skip
        assert stranger.delete(path).status_code in (
            404,
            405,
        )  # people are deactivated, not deleted
    for path in (f"/api/members/{membership.pk}/deactivate/", f"/api/members/{membership.pk}/reset-password/"):  # fmt: skip
        assert stranger.post(path).status_code == 404
    assert stranger.post("/api/cells/", {"organisation": organisation.pk, "name": "x"}, format="json").status_code == 400  # fmt: skip
    membership.refresh_from_db()
    assert membership.is_active
    assert Team.objects.filter(pk=team.pk, name="Crew").exists()
    assert Cell.objects.filter(organisation=organisation).count() == 1


def test_teams_and_cells_are_created_renamed_described_and_deleted(
    admin_client: APIClient, organisation: Organisation, operator: User
) -> None:
    membership = Membership.objects.get(user=operator)
    team = admin_client.post("/api/teams/", {"organisation": organisation.pk, "name": "Crew", "members": [membership.pk]}, format="json")  # fmt: skip
    assert team.status_code == 201
    assert team.data["members"] == [membership.pk]
    renamed = admin_client.patch(f"/api/teams/{team.data['id']}/", {"name": "Night"}, format="json")
    assert renamed.data["name"] == "Night"
    assert renamed.data["members"] == [membership.pk]
    assert admin_client.delete(f"/api/teams/{team.data['id']}/").status_code == 204
    cell = admin_client.post("/api/cells/", {"organisation": organisation.pk, "name": "weld"}, format="json")  # fmt: skip
    assert cell.status_code == 201
    described = admin_client.patch(f"/api/cells/{cell.data['id']}/", {"description": "By the door"}, format="json")  # fmt: skip
    assert described.data["description"] == "By the door"
    assert admin_client.patch(f"/api/cells/{cell.data['id']}/", {"name": "other"}, format="json").status_code == 400  # fmt: skip
    assert admin_client.delete(f"/api/cells/{cell.data['id']}/").status_code == 204
    records = admin_client.get("/api/admin-records/").data
    assert records["count"] == 6


def test_a_bad_cell_name_and_a_cell_with_cobots_are_refused(
    admin_client: APIClient, organisation: Organisation
) -> None:
    bad = admin_client.post("/api/cells/", {"organisation": organisation.pk, "name": "cell 1"}, format="json")  # fmt: skip
    assert bad.status_code == 400
    assert "name" in str(bad.data)
    make_cobot(organisation, name="welder", cell="weld")
    cell = Cell.objects.get(name="weld")
    kept = admin_client.delete(f"/api/cells/{cell.pk}/")
    assert kept.status_code == 400
    assert "welder" in str(kept.data)
    assert Cell.objects.filter(pk=cell.pk).exists()


@pytest.mark.parametrize("body", ["null", "1", "true"])
def test_a_cell_change_whose_body_is_no_object_is_a_400(
    admin_client: APIClient, organisation: Organisation, body: str
) -> None:
    cell = Cell.objects.create(organisation=organisation, name="weld", description="By the door")
    response = admin_client.patch(f"/api/cells/{cell.pk}/", body, content_type="application/json")
    assert response.status_code == 400
    assert response.json()["detail"].startswith("Invalid input: ")
    cell.refresh_from_db()
    assert cell.description == "By the door"


def test_a_cell_for_an_organisation_in_other_digits_than_ascii_is_refused(
    organisation: Organisation, other_organisation: Organisation
) -> None:
    """ "²" passes str.isdigit() and fails int() (a 500); "٢" is read as 2 by int()."""
    user = make_member(organisation, Role.ADMIN, "dana-double")
    organisation_services.add_member(other_organisation, user, Role.ENGINEER)
    arabic = str(other_organisation.pk).translate(str.maketrans("0123456789", "٠١٢٣٤٥٦٧٨٩"))
    client = _client(user)
    for written in ("²", arabic):
        response = client.post("/api/cells/", {"organisation": written, "name": "weld"}, format="json")  # fmt: skip
        assert response.status_code == 400
        assert "organisation" in response.data["fields"]
    assert not Cell.objects.filter(name="weld").exists()


def test_stop_and_resume_still_reach_the_tablets_views(operator_client: APIClient) -> None:
    assert resolve("/api/cells/stop/").func.view_class is StopCellView  # type: ignore[attr-defined]
    response = operator_client.post("/api/cells/stop/", {"cell": "nocobots"}, format="json")
    assert response.status_code not in (404, 405), response.content


def test_an_invitation_is_answered_instead_of_a_password(
    admin_client: APIClient, organisation: Organisation
) -> None:
    response = admin_client.post(
        "/api/members/",
        {"organisation": organisation.pk, "username": "ivy", "role": "operator", "invite": True},
        format="json",
    )
    assert response.status_code == 201
    assert "password" not in response.data
    assert "/organisation/join/" in response.data["invitation"]
