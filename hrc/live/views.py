"""The operator tablet page: /tablet/ (the whole floor) and /tablet/<cell>/.

The page is a shell; the tablet script (frontend/src/tablet/) fills it from
the live socket. Members of the organisation only: a user with no
organisation, or naming one that is not theirs (?organisation=<id>), gets 403.
A cell the organisation does not have gets a 404 page that says so and lists
the cells there are: a mistyped address must not look like a working tablet
whose STOP stops nothing.
"""

from django.contrib.auth.decorators import login_required
from django.core.exceptions import PermissionDenied
from django.http import HttpRequest, HttpResponse
from django.shortcuts import render
from django.views.decorators.csrf import ensure_csrf_cookie

from hrc.live import selectors
from hrc.organisations.selectors import cells_of


@login_required
@ensure_csrf_cookie
def tablet(request: HttpRequest, cell: str = "") -> HttpResponse:
    raw = request.GET.get("organisation", "")
    if raw and not raw.isdigit():
        raise PermissionDenied("organisation must be an id.")
    access = selectors.access_of(request.user, int(raw) if raw else None)
    if access is None:
        raise PermissionDenied("The tablet is for members of an organisation.")
    if not selectors.is_cell(access.organisation_id, cell):
        context = {
            "cell": cell,
            "organisation": selectors.organisation_name(access.organisation_id),
            "cells": cells_of(access.organisation_id),
        }
        return render(request, "tablet/unknown_cell.html", context, status=404)
    config = {
        "organisation": access.organisation_id,
        "cell": cell,
        "user": access.user_id,
        "socket": f"/ws/live/?organisation={access.organisation_id}&cell={cell}",
    }
    return render(request, "tablet/tablet.html", {"config": config, "cell": cell})
