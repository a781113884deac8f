"""The operator tablet page: /tablet/ (the whole floor) and /tablet/<cell>/.

The page is a shell; the tablet script (frontend/src/tablet/) fills it from
the live socket. Members of the organisation only: a user with no
organisation, or naming one that is not theirs (?organisation=<id>), gets 403.
"""

from django.contrib.auth.decorators import login_required
from django.core.exceptions import PermissionDenied
from django.http import HttpRequest, HttpResponse
from django.shortcuts import render
from django.views.decorators.csrf import ensure_csrf_cookie

from hrc.live import selectors


@login_required
@ensure_csrf_cookie
def tablet(request: HttpRequest, cell: str = "") -> HttpResponse:
    raw = request.GET.get("organisation", "")
    if raw and not raw.isdigit():
        raise PermissionDenied("organisation must be an id.")
    access = selectors.access_of(request.user, int(raw) if raw else None)
    if access is None:
        raise PermissionDenied("The tablet is for members of an organisation.")
    config = {
        "organisation": access.organisation_id,
        "cell": cell,
        "user": access.user_id,
        "socket": f"/ws/live/?organisation={access.organisation_id}&cell={cell}",
    }
    return render(request, "tablet/tablet.html", {"config": config, "cell": cell})
