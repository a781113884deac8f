"""The start page (/): what each role does first.

Operators go straight to their tablet; engineers and admins see their
organisation's patterns, cases and incidents (admins also its people, cells
and cobots); a person in no organisation is told so and whom to ask. Every
link leads to a page that lets the person in.
"""

from typing import Any

from django.http import HttpRequest, HttpResponse
from django.shortcuts import redirect, render

from hrc.cases.choices import OPEN_CASE_STATUSES
from hrc.cases.selectors import supervised_cases, supervised_incidents
from hrc.navigation import current_membership
from hrc.organisations.choices import Role
from hrc.organisations.models import Membership
from hrc.organisations.selectors import cells_of
from hrc.patterns.selectors import patterns_visible_to


def home(request: HttpRequest) -> HttpResponse:
    """Says what to do first: operators go to their tablet, the others see their work."""
    if not request.user.is_authenticated:
        return render(request, "home.html", {})
    membership = current_membership(request)
    if membership is None:
        return render(request, "home.html", {"no_organisation": True})
    if membership.role == Role.OPERATOR:
        return redirect("tablet")
    return render(request, "home.html", _start_of(request, membership))


def _start_of(request: HttpRequest, membership: Membership) -> dict[str, Any]:
    organisation_id = membership.organisation_id
    user = request.user
    return {
        "membership": membership,
        "is_admin": membership.role == Role.ADMIN,
        "pattern_count": patterns_visible_to(user).filter(organisation_id=organisation_id).count(),
        "open_case_count": supervised_cases(user)
        .filter(organisation_id=organisation_id, status__in=OPEN_CASE_STATUSES)
        .count(),
        "incident_count": supervised_incidents(user)
        .filter(case__organisation_id=organisation_id)
        .count(),
        "cell_count": cells_of(organisation_id).count(),
    }
