"""Every write to organisations, memberships and teams.

Each function validates with the model's own rules (`full_clean`) before it
saves, so the API, the admin and the management commands share one set of
checks; a broken rule raises django.core.exceptions.ValidationError.
"""

from collections.abc import Iterable

from django.contrib.auth import get_user_model
from django.contrib.auth.models import User
from django.core.exceptions import ValidationError
from django.db import transaction

from hrc.organisations.choices import Role
from hrc.organisations.models import Cell, Membership, Organisation, Team


def create_organisation(*, name: str, slug: str) -> Organisation:
    """Registers an organisation; `slug` must not be taken."""
    organisation = Organisation(name=name, slug=slug)
    organisation.full_clean()
    organisation.save()
    return organisation


def update_organisation(organisation: Organisation, *, name: str, slug: str) -> Organisation:
    """Renames an existing organisation; `slug` must not be taken by another one."""
    organisation.name = name
    organisation.slug = slug
    organisation.full_clean()
    organisation.save(update_fields=["name", "slug"])
    return organisation


def delete_organisation(organisation: Organisation) -> None:
    """Deletes the organisation and everything it owns.

    Raises django.db.models.ProtectedError while it has published pattern
    versions: those are an audit record and are not thrown away in passing.
    """
    organisation.delete()


def add_member(organisation: Organisation, user: User, role: Role | str) -> Membership:
    """Makes `user` a member with `role`; the user must not already be a member."""
    membership = Membership(organisation=organisation, user=user, role=role)
    membership.full_clean()
    membership.save()
    return membership


def change_role(membership: Membership, role: Role | str) -> Membership:
    """Gives an existing member another role in the same organisation."""
    membership.role = role
    membership.full_clean()
    membership.save(update_fields=["role"])
    return membership


def remove_member(membership: Membership) -> None:
    """Takes the user out of the organisation (and so out of its teams)."""
    membership.delete()


def create_team(organisation: Organisation, *, name: str) -> Team:
    """Creates an empty team; the name must be free in the organisation."""
    team = Team(organisation=organisation, name=name)
    team.full_clean()
    team.save()
    return team


def rename_team(team: Team, *, name: str) -> Team:
    """Renames an existing team; the name must be free in its organisation."""
    team.name = name
    team.full_clean()
    team.save(update_fields=["name"])
    return team


def set_team_members(team: Team, memberships: Iterable[Membership]) -> Team:
    """Replaces the team's members; every membership must be in the team's organisation."""
    members = list(memberships)
    strangers = [m for m in members if m.organisation_id != team.organisation_id]
    if strangers:
        names = ", ".join(str(m.user) for m in strangers)
        raise ValidationError(
            {"members": f"Only members of {team.organisation} can join its teams, not {names}."}
        )
    team.members.set(members)
    return team


def delete_team(team: Team) -> None:
    """Dissolves the team; its members stay in the organisation."""
    team.delete()


def ensure_cell(organisation: Organisation, name: str) -> Cell:
    """The organisation's cell of that name, registered now if it was not yet (a cobot placed there)."""
    cell = Cell.objects.filter(organisation=organisation, name=name).first()
    if cell is None:
        cell = Cell(organisation=organisation, name=name)
        cell.full_clean()
        cell, _ = Cell.objects.get_or_create(organisation=organisation, name=name)
    return cell


@transaction.atomic
def provision_user(
    username: str, *, password: str, is_staff: bool = False, is_superuser: bool = False
) -> User:
    """Creates the user, or resets an existing one's password and staff flags.

    Meant for set-up commands (the demo loader); people sign up through the admin.
    """
    user_model = get_user_model()
    user, _ = user_model.objects.get_or_create(username=username)
    assert isinstance(user, User)  # the project uses Django's stock user model
    user.set_password(password)
    user.is_staff = is_staff
    user.is_superuser = is_superuser
    user.is_active = True
    user.save()
    return user
