"""Where a signed-in person is and where they may go: the header, the start page, the switcher.

People in several organisations pick one (the header's switcher stores it in
the session); everyone else is simply in their only one. Pages that act on
"the organisation" (administration, starting a case) use current_membership.
The header offers each role only the places that let it in: operators their
tablets, engineers the patterns, cases, incidents, analytics and cobots,
admins also the organisation's administration, superusers also /admin/.
"""

from dataclasses import dataclass, field
from typing import Any

from django.contrib.auth.decorators import login_required
from django.http import HttpRequest, HttpResponse, HttpResponseRedirect
from django.shortcuts import render
from django.urls import reverse
from django.utils.functional import SimpleLazyObject
from django.views.decorators.http import require_POST

from hrc.organisations.choices import Role
from hrc.organisations.models import Membership
from hrc.organisations.selectors import cells_of, memberships_of

SESSION_KEY = "hrc.organisation"


def current_membership(request: HttpRequest) -> Membership | None:
    """The membership of the organisation the person chose, else their first; None for outsiders."""
    memberships = memberships_of(request.user).order_by("organisation__name")
    chosen = request.session.get(SESSION_KEY)
    if chosen is not None:
        membership = memberships.filter(organisation_id=chosen).first()
        if membership is not None:
            return membership
    return memberships.first()


# The header ---------------------------------------------------------------------------------


@dataclass(frozen=True)
class Place:
    """A link of the header; `current` marks the page the person is on (aria-current)."""

    label: str
    url: str
    current: bool = False


@dataclass(frozen=True)
class Navigation:
    """What the header shows a signed-in person."""

    membership: Membership | None
    places: list[Place]
    # The cells' tablets, for operators: a menu beside "Tablet".
    cells: list[Place] = field(default_factory=list)
    # Every membership, for the switcher; it is shown only when there are several.
    memberships: list[Membership] = field(default_factory=list)

    @property
    def switchable(self) -> bool:
        return len(self.memberships) > 1


# Administration is several pages (people, teams, cells); its link opens the first.
ADMINISTRATION = "/organisation/"


def navigation_of(request: HttpRequest) -> Navigation:
    """The header's places for the person's role in their current organisation."""
    membership = current_membership(request)
    role = Role(membership.role) if membership is not None else None
    links: list[tuple[str, str | None]] = []
    cells: list[tuple[str, str | None]] = []
    if role is Role.OPERATOR and membership is not None:
        links.append(("Tablet", reverse("tablet")))
        cells = [
            (cell.name, reverse("tablet-cell", args=[cell.name]))
            for cell in cells_of(membership.organisation_id)
        ]
    elif role in (Role.ENGINEER, Role.ADMIN):
        links += [
            ("Patterns", reverse("patterns:list")),
            ("Cases", reverse("cases:case-list")),
            ("Incidents", reverse("cases:incident-list")),
            ("Analytics", reverse("analytics:version-list")),
            ("Cobots", reverse("cobots:cobot-list")),
        ]
        if role is Role.ADMIN:
            links.append(("Administration", reverse("organisation:people")))
    if request.user.is_superuser:
        links.append(("Site admin", reverse("admin:index")))
    current = _current_url(request.path, [url for _, url in links + cells if url])
    return Navigation(
        membership=membership,
        places=[Place(label, url, url == current) for label, url in links if url],
        cells=[Place(label, url, url == current) for label, url in cells if url],
        memberships=list(memberships_of(request.user).order_by("organisation__name")),
    )


def _current_url(path: str, urls: list[str]) -> str | None:
    """The place the path lies in: the longest of the URLs whose section begins it."""
    inside = [url for url in urls if path.startswith(_section(url))]
    return max(inside, key=len, default=None)


def _section(url: str) -> str:
    return ADMINISTRATION if url.startswith(ADMINISTRATION) else url


def navigation(request: HttpRequest) -> dict[str, Any]:
    """Context processor: `navigation` for the header, read only by pages that show it."""
    if not request.user.is_authenticated:
        return {}
    return {"navigation": SimpleLazyObject(lambda: navigation_of(request))}


# The switcher -------------------------------------------------------------------------------


@login_required
@require_POST
def switch_organisation(request: HttpRequest) -> HttpResponse:
    """Works in the organisation posted as `organisation` from now on, then starts there.

    An id that is not a number is a 400; one of an organisation the person is
    not a member of is a 404, as if it did not exist. Nothing is stored then.
    """
    raw = request.POST.get("organisation", "")
    if not (raw.isascii() and raw.isdigit()):  # isdigit() alone takes "²", which int() refuses
        return _refused(request, 400, "organisation: choose one of your organisations.")
    if not memberships_of(request.user).filter(organisation_id=int(raw)).exists():
        return _refused(request, 404, "organisation: you are not a member of that organisation.")
    request.session[SESSION_KEY] = int(raw)
    return HttpResponseRedirect(reverse("home"))


def _refused(request: HttpRequest, status: int, message: str) -> HttpResponse:
    return render(request, "refused.html", {"message": message}, status=status)
