from django.contrib.auth.models import User
from rest_framework.test import APIClient

from hrc.organisations.models import Organisation


def test_members_list_only_their_own_organisation(
    operator_client: APIClient, organisation: Organisation, other_organisation: Organisation
) -> None:
    response = operator_client.get("/api/organisations/")
    assert response.status_code == 200
    assert [o["slug"] for o in response.data["results"]] == [organisation.slug]


def test_a_user_without_membership_sees_no_organisation(loner_client: APIClient) -> None:
    response = loner_client.get("/api/organisations/")
    assert response.status_code == 200
    assert response.data["results"] == []


def test_another_organisation_is_not_found(
    outsider_client: APIClient, organisation: Organisation
) -> None:
    assert outsider_client.get(f"/api/organisations/{organisation.pk}/").status_code == 404


def test_me_lists_each_membership_with_its_role(
    engineer_client: APIClient, engineer: User, organisation: Organisation
) -> None:
    response = engineer_client.get("/api/organisations/me/")
    assert response.status_code == 200
    assert response.data["username"] == engineer.username
    assert response.data["memberships"] == [
        {
            "organisation": {
                "id": organisation.pk,
                "name": "Home plant",
                "slug": organisation.slug,
            },
            "role": "engineer",
        }
    ]


def test_me_of_a_user_without_membership_has_none(loner_client: APIClient) -> None:
    assert loner_client.get("/api/organisations/me/").data["memberships"] == []


def test_organisations_cannot_be_changed_over_the_api(
    admin_client: APIClient, organisation: Organisation
) -> None:
    url = f"/api/organisations/{organisation.pk}/"
    assert admin_client.patch(url, {"name": "Renamed"}, format="json").status_code == 405
    organisation.refresh_from_db()
    assert organisation.name == "Home plant"
