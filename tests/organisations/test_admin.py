import pytest
from django.contrib.auth.models import User
from django.test import Client

from hrc.organisations import services
from hrc.organisations.models import AdminRecord, Membership, Organisation, Team
from tests import factories


def _inline_management(prefix: str, total: int, initial: int = 0) -> dict[str, str]:
    return {
        f"{prefix}-TOTAL_FORMS": str(total),
        f"{prefix}-INITIAL_FORMS": str(initial),
        f"{prefix}-MIN_NUM_FORMS": "0",
        f"{prefix}-MAX_NUM_FORMS": "1000",
    }


@pytest.mark.parametrize(
    "url",
    [
        "/admin/organisations/organisation/",
        "/admin/organisations/organisation/add/",
        "/admin/organisations/membership/",
        "/admin/organisations/team/",
        "/admin/organisations/team/add/",
        "/admin/organisations/organisation/?q=home",
        "/admin/organisations/membership/?q=erik&role__exact=engineer",
        "/admin/organisations/team/?q=erik",
    ],
)
def test_admin_pages_render(staff_client: Client, engineer: User, url: str) -> None:
    assert staff_client.get(url).status_code == 200


def test_the_admin_is_closed_to_members_who_are_not_staff(engineer: User) -> None:
    client = Client()
    client.force_login(engineer)
    response = client.get("/admin/organisations/organisation/")
    assert response.status_code == 302
    assert "/admin/login/" in response["Location"]


def test_adding_an_organisation_with_an_inline_member_creates_the_membership(
    staff_client: Client,
) -> None:
    person = factories.make_user("newcomer")
    data = {
        "name": "New plant",
        "slug": "new-plant",
        **_inline_management("memberships", total=1),
        "memberships-0-user": str(person.pk),
        "memberships-0-role": "engineer",
    }
    response = staff_client.post("/admin/organisations/organisation/add/", data)
    assert response.status_code == 302, response.content.decode()[:2000]
    organisation = Organisation.objects.get(slug="new-plant")
    assert Membership.objects.get(organisation=organisation, user=person).role == "engineer"


def test_the_inline_changes_the_role_but_keeps_the_person(
    staff_client: Client, organisation: Organisation, operator: User, engineer: User
) -> None:
    membership = Membership.objects.get(user=operator)
    data = {
        "name": organisation.name,
        "slug": organisation.slug,
        **_inline_management("memberships", total=1, initial=1),
        "memberships-0-id": str(membership.pk),
        "memberships-0-organisation": str(organisation.pk),
        # The user field is disabled for existing rows: a different person here is ignored.
        "memberships-0-user": str(engineer.pk),
        "memberships-0-role": "admin",
    }
    url = f"/admin/organisations/organisation/{organisation.pk}/change/"
    response = staff_client.post(url, data)
    assert response.status_code == 302, response.content.decode()[:2000]
    membership.refresh_from_db()
    assert (membership.user, membership.role) == (operator, "admin")


def test_a_team_cannot_take_members_of_another_organisation(
    staff_client: Client, organisation: Organisation, outsider: User
) -> None:
    stranger = Membership.objects.get(user=outsider)
    data = {"organisation": str(organisation.pk), "name": "Night shift", "members": [stranger.pk]}
    response = staff_client.post("/admin/organisations/team/add/", data)
    assert response.status_code == 200  # the form comes back with the error
    assert "Only members of Home plant" in response.content.decode()
    assert not Team.objects.exists()


def test_the_admin_site_refuses_staff_who_are_not_superusers(db: None) -> None:
    staff = services.provision_user("clerk", password="a-test-password", is_staff=True)
    client = Client()
    client.force_login(staff)
    response = client.get("/admin/")
    assert response.status_code == 302
    assert response["Location"].startswith("/admin/login/")
    assert client.get("/admin/organisations/organisation/").status_code == 302


def test_a_superuser_reads_the_administration_records_but_cannot_change_them(
    staff_client: Client, organisation: Organisation
) -> None:
    record = services.add_cell(organisation, by=factories.make_user(), name="weld")
    assert staff_client.get("/admin/organisations/adminrecord/").status_code == 200
    entry = AdminRecord.objects.get(target=record.name)
    assert staff_client.post(f"/admin/organisations/adminrecord/{entry.pk}/delete/", {"post": "yes"}).status_code == 403  # fmt: skip
    assert AdminRecord.objects.filter(pk=entry.pk).exists()
