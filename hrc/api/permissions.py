"""Who may do what, inside the organisation wall.

The wall itself is the querysets: every view lists only the objects of the
user's organisations, so an outsider gets 404 and empty lists. The role check
below comes after: any member reads, engineers and admins write, operators
get 403 on writes.
"""

from typing import Any

from rest_framework.exceptions import PermissionDenied, ValidationError
from rest_framework.permissions import SAFE_METHODS, BasePermission
from rest_framework.request import Request
from rest_framework.views import APIView

from hrc.organisations.models import Organisation
from hrc.organisations.selectors import (
    may_write_in,
    organisations_of,
    writable_organisations,
)

WRITERS_ONLY = "Only engineers and admins of the organisation may change this."


class MembersReadWritersWrite(BasePermission):
    """Members read; engineers and admins write. Views may name `read_actions`: POSTs that change nothing."""

    message = WRITERS_ONLY

    def has_permission(self, request: Request, view: APIView) -> bool:
        if not (request.user and request.user.is_authenticated):
            return False
        if _is_read(request, view):
            return True
        if getattr(view, "detail", False):
            return True  # decided per object, once the object is known to be visible
        # Creating: the target organisation is checked by target_organisation(); refuse
        # early anyone who may write nowhere.
        return writable_organisations(request.user).exists()

    def has_object_permission(self, request: Request, view: APIView, obj: Any) -> bool:
        if _is_read(request, view):
            return True
        return may_write_in(request.user, _organisation_id(obj))


def target_organisation(request: Request, requested: Organisation | int | None) -> Organisation:
    """The organisation a new object goes into: the requested one, or the user's only one.

    Raises ValidationError (400) when the request must say which, or names an
    organisation the user is not in (not 404-worthy: nothing is being looked
    up); PermissionDenied (403) when the user may not write there.
    """
    if requested is None:
        writable = list(writable_organisations(request.user)[:2])
        if len(writable) == 1:
            return writable[0]
        if not writable:
            raise PermissionDenied(WRITERS_ONLY)
        raise ValidationError(
            {"organisation": "You belong to several organisations: say which one (its id)."}
        )
    requested_id = requested.pk if isinstance(requested, Organisation) else requested
    organisation = organisations_of(request.user).filter(pk=requested_id).first()
    if organisation is None:
        raise ValidationError(
            {"organisation": f"You are not a member of organisation {requested_id}."}
        )
    if not may_write_in(request.user, organisation.pk):
        raise PermissionDenied(WRITERS_ONLY)
    return organisation


def _is_read(request: Request, view: APIView) -> bool:
    return request.method in SAFE_METHODS or getattr(view, "action", None) in getattr(
        view, "read_actions", ()
    )


def _organisation_id(obj: Any) -> int:
    organisation_id = getattr(obj, "organisation_id", None)
    if not isinstance(organisation_id, int):
        raise TypeError(f"{type(obj).__name__} has no organisation to check the role in")
    return organisation_id
