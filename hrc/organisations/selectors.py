"""Reads about who belongs where; every permission check of the API starts here.

Functions take any user, signed in or not: an anonymous user belongs nowhere.
"""

from django.contrib.auth.models import AbstractBaseUser, AnonymousUser
from django.db.models import QuerySet
from django.utils import timezone

from hrc.organisations.choices import WRITER_ROLES, Role
from hrc.organisations.models import AdminRecord, ApiToken, Cell, Membership, Organisation, Team

AnyUser = AbstractBaseUser | AnonymousUser


def memberships_of(user: AnyUser) -> QuerySet[Membership]:
    """The user's memberships with their organisations; empty for an anonymous user."""
    if not user.is_authenticated:
        return Membership.objects.none()
    return Membership.objects.filter(user_id=user.pk, is_active=True).select_related("organisation")


def organisations_of(user: AnyUser) -> QuerySet[Organisation]:
    """The organisations whose data the user may read."""
    if not user.is_authenticated:
        return Organisation.objects.none()
    return Organisation.objects.filter(memberships__user_id=user.pk, memberships__is_active=True)


def writable_organisations(user: AnyUser) -> QuerySet[Organisation]:
    """The organisations whose models and cobots the user may change."""
    if not user.is_authenticated:
        return Organisation.objects.none()
    # One filter() call: both conditions must hold for the same membership row.
    return Organisation.objects.filter(
        memberships__user_id=user.pk,
        memberships__role__in=WRITER_ROLES,
        memberships__is_active=True,
    )


def role_in(user: AnyUser, organisation_id: int) -> Role | None:
    """The user's role in the organisation; None when they are not a member."""
    membership = memberships_of(user).filter(organisation_id=organisation_id).first()
    return Role(membership.role) if membership else None


def may_write_in(user: AnyUser, organisation_id: int) -> bool:
    """Whether the user may change the organisation's models and cobots."""
    return role_in(user, organisation_id) in WRITER_ROLES


def cells_of(organisation_id: int) -> QuerySet[Cell]:
    """The organisation's cells by name."""
    return Cell.objects.filter(organisation_id=organisation_id).order_by("name")


def is_admin_of(user: AnyUser, organisation_id: int) -> bool:
    """Whether the user is an active admin of the organisation (the administration's check)."""
    return role_in(user, organisation_id) == Role.ADMIN


def members_of(organisation_id: int) -> QuerySet[Membership]:
    """Everyone who is or was a member, with their user and teams, active ones first."""
    return (
        Membership.objects.filter(organisation_id=organisation_id)
        .select_related("user")
        .prefetch_related("teams")
        .order_by("-is_active", "user__username")
    )


def teams_of(organisation_id: int) -> QuerySet[Team]:
    """The organisation's teams by name, with their members' users."""
    return (
        Team.objects.filter(organisation_id=organisation_id)
        .prefetch_related("members__user")
        .order_by("name")
    )


def admin_records_of(organisation_id: int) -> QuerySet[AdminRecord]:
    """The organisation's administration record, latest first."""
    return AdminRecord.objects.filter(organisation_id=organisation_id).select_related("actor")


def admin_organisations_of(user: AnyUser) -> QuerySet[Organisation]:
    """The organisations the user is an active admin of."""
    if not user.is_authenticated:
        return Organisation.objects.none()
    return Organisation.objects.filter(
        memberships__user_id=user.pk, memberships__role=Role.ADMIN, memberships__is_active=True
    )


def api_token_of(digest: str) -> ApiToken | None:
    """The live (unexpired) token with this digest, with its user; one query."""
    return (
        ApiToken.objects.select_related("user")
        .filter(digest=digest, expires_at__gt=timezone.now())
        .first()
    )
