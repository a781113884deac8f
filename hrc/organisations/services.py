"""Every write to organisations, memberships and teams.

Each function validates with the model's own rules (`full_clean`) before it
saves, so the API, the admin and the management commands share one set of
checks; a broken rule raises django.core.exceptions.ValidationError.
"""

import hashlib
import secrets
from collections.abc import Iterable, Mapping
from datetime import timedelta
from typing import Any

from django.conf import settings
from django.contrib.auth import get_user_model
from django.contrib.auth.models import User
from django.contrib.auth.tokens import default_token_generator
from django.core.exceptions import ValidationError
from django.db import transaction
from django.utils import timezone
from django.utils.encoding import force_bytes
from django.utils.http import urlsafe_base64_encode

from hrc.organisations import hooks
from hrc.organisations.choices import AdminAction, Role
from hrc.organisations.models import (
    AdminRecord,
    ApiToken,
    Cell,
    Membership,
    Organisation,
    Team,
)

# A script that asks for a key on every run would otherwise pile them up; past this many
# live ones, issuing another retires the oldest.
API_TOKENS_PER_USER = 20


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
    """Takes the user out of the organisation (and so out of its teams); their API keys go
    and their live sockets in it close (hooks.membership_ended)."""
    user, organisation_id = membership.user, membership.organisation_id
    membership.delete()
    revoke_api_tokens(user)
    hooks.membership_ended(user.pk, organisation_id)


def digest_of(key: str) -> str:
    """How an API key is stored and looked up."""
    return hashlib.sha256(key.encode()).hexdigest()


def issue_api_token(user: User) -> tuple[str, ApiToken]:
    """A new API key for `user` (shown once: only its digest is kept) and its row; expired
    keys of the user are forgotten, and the oldest live ones past API_TOKENS_PER_USER."""
    key = secrets.token_urlsafe(30)  # 40 characters
    now = timezone.now()
    lifetime = timedelta(hours=settings.HRC_API_TOKEN_HOURS)
    with transaction.atomic():
        ApiToken.objects.filter(user=user, expires_at__lte=now).delete()
        kept = ApiToken.objects.filter(user=user).values_list("pk", flat=True)
        ApiToken.objects.filter(pk__in=list(kept[API_TOKENS_PER_USER - 1 :])).delete()
        token = ApiToken.objects.create(user=user, digest=digest_of(key), expires_at=now + lifetime)
    return key, token


def revoke_api_tokens_on_new_password(sender: type[User], instance: User, **kwargs: Any) -> None:
    """post_save of a user: set_password() leaves the new raw password on the instance
    until the save is over, so its presence says the password just changed."""
    if getattr(instance, "_password", None) is not None:
        revoke_api_tokens(instance)


def revoke_api_tokens(user: User) -> int:
    """Every API key of `user` stops working at once; returns how many there were."""
    deleted, _ = ApiToken.objects.filter(user=user).delete()
    return deleted


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


# The organisation's own administration ------------------------------------------------
#
# What an organisation's admin does on /organisation/ and through the API. Each takes the
# admin (`by`), whose role the caller has checked, writes in one transaction and leaves an
# AdminRecord. Bad values raise ValidationError keyed by the field, before anything is written.


def record_admin_action(
    organisation: Organisation,
    by: User | None,
    action: AdminAction,
    target: str,
    detail: Mapping[str, Any] | None = None,
) -> AdminRecord:
    """Appends one entry to the organisation's administration record."""
    return AdminRecord.objects.create(
        organisation=organisation, actor=by, action=action, target=target, detail=dict(detail or {})
    )


def one_time_password() -> str:
    """16 URL-safe characters (96 bits), shown to the admin once and never stored in clear."""
    return secrets.token_urlsafe(12)


@transaction.atomic
def add_person(
    organisation: Organisation,
    *,
    by: User,
    username: str,
    name: str = "",
    email: str = "",
    role: Role | str,
    teams: Iterable[Team] = (),
    invite: bool = False,
) -> tuple[Membership, str]:
    """Creates a new user who belongs to the organisation with `role` and is in `teams`.

    Returns the membership and the one-time password, which the caller shows once; with
    `invite`, the user has no usable password yet and the second value is "" (the caller
    hands over invitation_for(user) instead). The username must be free, the teams the
    organisation's.
    """
    user_model = get_user_model()
    if user_model.objects.filter(username__iexact=username).exists():
        raise ValidationError({"username": f"The username {username} is taken."})
    first, _, last = name.strip().partition(" ")
    user = user_model(username=username, first_name=first, last_name=last, email=email)
    password = "" if invite else one_time_password()
    if invite:
        user.set_unusable_password()
    else:
        user.set_password(password)
    user.full_clean()
    teams = list(teams)
    _check_teams(organisation, teams)
    assert isinstance(user, User)  # the project uses Django's stock user model
    user.save()
    membership = Membership(organisation=organisation, user=user, role=role)
    membership.full_clean()
    membership.save()
    membership.teams.set(teams)
    record_admin_action(
        organisation, by, AdminAction.PERSON_ADDED, username,
        {"role": str(role), "teams": [t.name for t in teams], "invited": invite},
    )  # fmt: skip
    return membership, password


def invitation_for(user: User) -> tuple[str, str]:
    """The (uidb64, token) of the user's invitation link (organisation:join).

    Django's password-reset token: signed with the secret key, it expires after
    PASSWORD_RESET_TIMEOUT and is spent once the password changes, so it works once.
    """
    return urlsafe_base64_encode(force_bytes(user.pk)), default_token_generator.make_token(user)


def invitation_valid(user: User, token: str) -> bool:
    """Whether the invitation link still works: not used, not expired, the user not deactivated."""
    return user.is_active and default_token_generator.check_token(user, token)


@transaction.atomic
def accept_invitation(user: User, token: str, password: str) -> None:
    """Sets the invited user's own password; ValidationError when the token is spent or expired.

    The caller has checked `password` with the password validators.
    """
    if not invitation_valid(user, token):
        raise ValidationError({"token": "This invitation link has been used or has expired: ask your admin for a new one."})  # fmt: skip
    user.set_password(password)
    user.save(update_fields=["password"])
    for membership in Membership.objects.filter(user=user, is_active=True).select_related("organisation"):  # fmt: skip
        record_admin_action(
            membership.organisation, user, AdminAction.INVITATION_ACCEPTED, user.username
        )


def _check_teams(organisation: Organisation, teams: Iterable[Team]) -> None:
    strangers = [t.name for t in teams if t.organisation_id != organisation.pk]
    if strangers:
        raise ValidationError({"teams": f"Not a team of {organisation}: {', '.join(strangers)}."})


def _check_not_last_admin(membership: Membership, doing: str) -> None:
    others = Membership.objects.filter(
        organisation_id=membership.organisation_id, role=Role.ADMIN, is_active=True
    ).exclude(pk=membership.pk)
    if membership.role == Role.ADMIN and not others.exists():
        raise ValidationError(
            {
                "role": f"{membership.user} is the organisation's last admin and cannot be {doing}: make another admin first."
            }
        )


@transaction.atomic
def change_member_role(membership: Membership, role: Role | str, *, by: User) -> Membership:
    """Gives the member another role; the last active admin keeps theirs."""
    if role != Role.ADMIN:
        _check_not_last_admin(membership, "demoted")
    before = membership.role
    change_role(membership, role)
    record_admin_action(
        membership.organisation, by, AdminAction.ROLE_CHANGED, membership.user.username,
        {"from": before, "to": str(role)},
    )  # fmt: skip
    return membership


@transaction.atomic
def set_member_teams(membership: Membership, teams: Iterable[Team], *, by: User) -> Membership:
    """Puts the member in exactly `teams`, all of the member's organisation."""
    teams = list(teams)
    _check_teams(membership.organisation, teams)
    membership.teams.set(teams)
    record_admin_action(
        membership.organisation, by, AdminAction.TEAMS_CHANGED, membership.user.username,
        {"teams": [t.name for t in teams]},
    )  # fmt: skip
    return membership


@transaction.atomic
def deactivate_member(membership: Membership, *, by: User) -> int:
    """Ends the person's work in the organisation and gives back the tasks they claimed.

    The membership stays (the record and the case logs name them) but no longer
    counts; they leave its teams. A user with no other active membership can no
    longer sign in. The last active admin cannot be deactivated. Returns the number
    of tasks given back.
    """
    if not membership.is_active:
        raise ValidationError({"is_active": f"{membership.user} is deactivated already."})
    _check_not_last_admin(membership, "deactivated")
    membership.is_active = False
    membership.save(update_fields=["is_active"])
    membership.teams.clear()
    user = membership.user
    if not Membership.objects.filter(user=user, is_active=True).exists():
        user.is_active = False
        user.save(update_fields=["is_active"])
    handed_back = hooks.hand_back_work(user, membership.organisation_id, by)
    revoke_api_tokens(user)
    hooks.membership_ended(user.pk, membership.organisation_id)
    record_admin_action(
        membership.organisation, by, AdminAction.PERSON_DEACTIVATED, user.username,
        {"tasks_handed_back": handed_back, "signs_in": user.is_active},
    )  # fmt: skip
    return handed_back


@transaction.atomic
def reset_member_password(membership: Membership, *, by: User) -> str:
    """Sets a new one-time password for an active member and returns it, to be shown once."""
    if not membership.is_active:
        raise ValidationError({"is_active": f"{membership.user} is deactivated."})
    password = one_time_password()
    membership.user.set_password(password)
    membership.user.save(update_fields=["password"])
    record_admin_action(
        membership.organisation, by, AdminAction.PASSWORD_RESET, membership.user.username
    )
    return password


@transaction.atomic
def add_team(
    organisation: Organisation, *, by: User, name: str, members: Iterable[Membership] = ()
) -> Team:
    """Creates a team with `members` (the organisation's active members)."""
    team = create_team(organisation, name=name)
    members = list(members)
    set_team_members(team, members)
    record_admin_action(
        organisation, by, AdminAction.TEAM_CREATED, name,
        {"members": [m.user.username for m in members]},
    )  # fmt: skip
    return team


@transaction.atomic
def change_team(team: Team, *, by: User, name: str, members: Iterable[Membership]) -> Team:
    """Renames the team and replaces its members."""
    before = team.name
    rename_team(team, name=name)
    members = list(members)
    set_team_members(team, members)
    record_admin_action(
        team.organisation, by, AdminAction.TEAM_CHANGED, name,
        {"was": before, "members": [m.user.username for m in members]},
    )  # fmt: skip
    return team


@transaction.atomic
def remove_team(team: Team, *, by: User) -> None:
    """Dissolves the team and records it."""
    record_admin_action(team.organisation, by, AdminAction.TEAM_DELETED, team.name)
    delete_team(team)


@transaction.atomic
def add_cell(organisation: Organisation, *, by: User, name: str, description: str = "") -> Cell:
    """Registers a cell; the name must be valid and free in the organisation."""
    cell = Cell(organisation=organisation, name=name, description=description)
    cell.full_clean()
    cell.save()
    record_admin_action(
        organisation, by, AdminAction.CELL_CREATED, name, {"description": description}
    )
    return cell


@transaction.atomic
def describe_cell(cell: Cell, *, by: User, description: str) -> Cell:
    """Changes the cell's description (its name is its tablet's address and stays)."""
    cell.description = description
    cell.full_clean()
    cell.save(update_fields=["description"])
    record_admin_action(
        cell.organisation, by, AdminAction.CELL_CHANGED, cell.name, {"description": description}
    )
    return cell


@transaction.atomic
def remove_cell(cell: Cell, *, by: User) -> None:
    """Forgets the cell; refused while cobots stand in it (hooks.cell_occupants)."""
    standing = hooks.cell_occupants(cell.organisation_id, cell.name)
    if standing:
        raise ValidationError(
            {"name": f"Cobots stand in {cell.name}: {', '.join(standing)}. Move them first."}
        )
    record_admin_action(cell.organisation, by, AdminAction.CELL_DELETED, cell.name)
    cell.delete()
