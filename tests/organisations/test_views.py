"""The administration pages: admins of the organisation only, input checked at its field."""

from __future__ import annotations

import re

import pytest
from django.contrib.auth.models import User
from django.test import Client
from django.utils.http import urlsafe_base64_encode

from hrc.organisations.choices import AdminAction, Role
from hrc.organisations.models import AdminRecord, Cell, Membership, Organisation, Team
from hrc.organisations.services import invitation_for
from tests.factories import make_cobot, make_member

pytestmark = pytest.mark.django_db


def _browser(user: User) -> Client:
    client = Client()
    client.force_login(user)
    return client


@pytest.fixture
def page(admin: User) -> Client:
    return _browser(admin)


def test_an_admin_adds_an_operator_who_signs_in_with_the_password_shown_once(
    page: Client, organisation: Organisation
) -> None:
    team = Team.objects.create(organisation=organisation, name="Shift A")
    response = page.post(
        "/organisation/people/",
        {"username": "ada", "name": "Ada Lovelace", "email": "ada@example.org",
         "role": Role.OPERATOR, "teams": [team.pk]},
    )  # fmt: skip
    assert response.status_code == 200
    password = re.search(r"<code>([^<]+)</code>", response.content.decode())
    assert password is not None
    membership = Membership.objects.get(user__username="ada", organisation=organisation)
    assert membership.role == Role.OPERATOR
    assert list(membership.teams.all()) == [team]
    assert Client().login(username="ada", password=password.group(1))
    assert "<code>" not in page.get("/organisation/people/").content.decode()
    record = AdminRecord.objects.get(action=AdminAction.PERSON_ADDED)
    assert record.target == "ada"
    assert record.organisation == organisation


def test_a_taken_username_is_refused_at_its_field_and_nothing_is_written(
    page: Client, organisation: Organisation, operator: User
) -> None:
    before = (User.objects.count(), AdminRecord.objects.count())
    response = page.post(
        "/organisation/people/", {"username": operator.username, "role": Role.OPERATOR}
    )
    assert response.status_code == 400
    assert "id_username-errors" in response.content.decode()
    assert (User.objects.count(), AdminRecord.objects.count()) == before


def test_a_team_of_another_organisation_is_refused_at_its_field(
    page: Client, other_organisation: Organisation
) -> None:
    stranger = Team.objects.create(organisation=other_organisation, name="Theirs")
    response = page.post(
        "/organisation/people/", {"username": "bob", "role": Role.OPERATOR, "teams": [stranger.pk]}
    )
    assert response.status_code == 400
    assert "id_teams-errors" in response.content.decode()
    assert not User.objects.filter(username="bob").exists()


def test_a_bad_cell_name_is_refused_at_its_field(page: Client) -> None:
    response = page.post("/organisation/cells/", {"name": "cell 1", "description": ""})
    assert response.status_code == 400
    assert "id_name-errors" in response.content.decode()
    assert not Cell.objects.exists()


def test_a_cell_with_a_cobot_is_not_deleted_and_the_page_names_the_cobot(
    page: Client, organisation: Organisation
) -> None:
    make_cobot(organisation, cell="weld")
    cell = Cell.objects.get(organisation=organisation, name="weld")
    response = page.post(f"/organisation/cells/{cell.pk}/", {"delete": "1"})
    assert response.status_code == 400
    assert "Cobots stand in weld" in response.content.decode()
    assert Cell.objects.filter(pk=cell.pk).exists()


def test_an_admin_creates_and_deletes_a_team_and_a_cell(
    page: Client, organisation: Organisation, operator: User
) -> None:
    membership = Membership.objects.get(user=operator)
    assert (
        page.post("/organisation/teams/", {"name": "Crew", "members": [membership.pk]}).status_code
        == 302
    )
    team = Team.objects.get(organisation=organisation, name="Crew")
    assert list(team.members.all()) == [membership]
    assert page.post(f"/organisation/teams/{team.pk}/", {"delete": "1"}).status_code == 302
    assert page.post("/organisation/cells/", {"name": "cell1", "description": "By the door"}).status_code == 302  # fmt: skip
    cell = Cell.objects.get(organisation=organisation, name="cell1")
    assert "/tablet/cell1/" in page.get("/organisation/cells/").content.decode()
    assert page.post(f"/organisation/cells/{cell.pk}/", {"delete": "1"}).status_code == 302
    actions = set(AdminRecord.objects.values_list("action", flat=True))
    assert {AdminAction.TEAM_CREATED, AdminAction.TEAM_DELETED, AdminAction.CELL_CREATED, AdminAction.CELL_DELETED} <= actions  # fmt: skip


def test_the_last_admin_cannot_demote_or_deactivate_themselves(page: Client, admin: User) -> None:
    membership = Membership.objects.get(user=admin)
    response = page.post(f"/organisation/people/{membership.pk}/", {"role": Role.ENGINEER})
    assert response.status_code == 400
    assert "last admin" in response.content.decode()
    response = page.post(f"/organisation/people/{membership.pk}/deactivate/")
    assert response.status_code == 400
    membership.refresh_from_db()
    assert membership.role == Role.ADMIN
    assert membership.is_active


def test_deactivating_a_person_with_no_other_organisation_stops_their_sign_in(
    page: Client, operator: User
) -> None:
    membership = Membership.objects.get(user=operator)
    assert page.post(f"/organisation/people/{membership.pk}/deactivate/").status_code == 200
    membership.refresh_from_db()
    operator.refresh_from_db()
    assert not membership.is_active
    assert not operator.is_active


def test_deactivating_keeps_the_sign_in_for_another_organisation(
    page: Client, organisation: Organisation, operator: User, other_organisation: Organisation
) -> None:
    Membership.objects.create(user=operator, organisation=other_organisation, role=Role.OPERATOR)
    membership = Membership.objects.get(user=operator, organisation=organisation)
    assert page.post(f"/organisation/people/{membership.pk}/deactivate/").status_code == 200
    operator.refresh_from_db()
    assert operator.is_active


def test_a_password_reset_shows_a_new_password_that_signs_in(page: Client, operator: User) -> None:
    membership = Membership.objects.get(user=operator)
    response = page.post(f"/organisation/people/{membership.pk}/reset-password/")
    password = re.search(r"<code>([^<]+)</code>", response.content.decode())
    assert password is not None
    assert Client().login(username=operator.username, password=password.group(1))


@pytest.mark.parametrize(
    "path", ["/organisation/people/", "/organisation/teams/", "/organisation/cells/"]
)
def test_engineers_and_operators_are_refused(path: str, engineer: User, operator: User) -> None:
    for user in (engineer, operator):
        assert _browser(user).get(path).status_code == 403
        assert _browser(user).post(path, {"name": "x", "username": "x", "role": "operator"}).status_code == 403  # fmt: skip
    assert not Team.objects.exists()
    assert not Cell.objects.exists()
    assert not User.objects.filter(username="x").exists()


def test_an_admin_of_another_organisation_sees_nothing_of_this_one(
    organisation: Organisation, other_organisation: Organisation, operator: User, admin: User
) -> None:
    team = Team.objects.create(organisation=organisation, name="Our crew")
    cell = Cell.objects.create(organisation=organisation, name="ourcell")
    membership = Membership.objects.get(user=operator)
    stranger = _browser(make_member(other_organisation, Role.ADMIN))
    for path in ("/organisation/people/", "/organisation/teams/", "/organisation/cells/"):
        text = stranger.get(path).content.decode()
        assert operator.username not in text
        assert "Our crew" not in text
        assert "ourcell" not in text
    for path in (
        f"/organisation/people/{membership.pk}/",
        f"/organisation/teams/{team.pk}/",
        f"/organisation/cells/{cell.pk}/",
    ):
        assert stranger.get(path).status_code == 404
        assert stranger.post(path, {"delete": "1", "role": "admin"}).status_code == 404
    for path in (f"/organisation/people/{membership.pk}/deactivate/", f"/organisation/people/{membership.pk}/reset-password/"):  # fmt: skip
        assert stranger.post(path).status_code == 404
    membership.refresh_from_db()
    assert membership.is_active
    assert Team.objects.filter(pk=team.pk).exists()


def test_an_invited_person_chooses_their_password_once_through_the_link(
    page: Client, organisation: Organisation
) -> None:
    response = page.post(
        "/organisation/people/", {"username": "ivy", "role": Role.OPERATOR, "invite": "on"}
    )
    link = re.search(r'<code id="invitation">http://testserver([^<]+)</code>', response.content.decode())  # fmt: skip
    assert link is not None
    ivy = User.objects.get(username="ivy")
    assert not ivy.has_usable_password()
    stranger = Client()
    assert stranger.get(link.group(1)).status_code == 200
    bad = stranger.post(link.group(1), {"new_password1": "short", "new_password2": "short"})
    assert bad.status_code == 400
    assert "id_new_password2-errors" in bad.content.decode()
    chosen = "a-long-chosen-password-42"
    done = stranger.post(link.group(1), {"new_password1": chosen, "new_password2": chosen})
    assert done.status_code == 302
    assert Client().login(username="ivy", password=chosen)
    again = stranger.post(link.group(1), {"new_password1": "x" + chosen, "new_password2": "x" + chosen})  # fmt: skip
    assert again.status_code == 404
    assert Client().login(username="ivy", password=chosen)
    assert AdminRecord.objects.filter(action=AdminAction.INVITATION_ACCEPTED, actor__username="ivy").exists()  # fmt: skip


def test_a_forged_invitation_link_is_refused(page: Client, operator: User) -> None:
    uid, _ = invitation_for(operator)
    assert Client().get(f"/organisation/join/{uid}/forged-token/").status_code == 404
    assert Client().get("/organisation/join/!!/forged-token/").status_code == 404


def test_an_invitation_link_with_the_id_in_other_digits_than_ascii_is_refused(
    operator: User,
) -> None:
    _, token = invitation_for(operator)
    arabic = str(operator.pk).translate(str.maketrans("0123456789", "٠١٢٣٤٥٦٧٨٩"))
    uid = urlsafe_base64_encode(arabic.encode())
    assert Client().get(f"/organisation/join/{uid}/{token}/").status_code == 404
    assert (
        Client().get(f"/organisation/join/{invitation_for(operator)[0]}/{token}/").status_code
        == 200
    )
