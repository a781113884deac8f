"""The operator tablet page: /tablet/ (the whole floor) and /tablet/<cell>/, and starting a cycle there.

The page is a shell; the tablet script (frontend/src/tablet/) fills it from
the live socket. Members of the organisation only: a user with no
organisation, or naming one that is not theirs (?organisation=<id>), gets 403.
A cell the organisation does not have is a 404 page that lists its cells, so
a mistyped address never shows a tablet whose STOP stops nothing. A cell's
tablet also offers the versions its operators may start there (the version's
start rights), each with its start data form.
"""

from typing import Any

from django.contrib.auth.decorators import login_required
from django.contrib.auth.models import User
from django.core.exceptions import PermissionDenied
from django.http import Http404, HttpRequest, HttpResponse
from django.shortcuts import redirect, render
from django.urls import reverse
from django.views.decorators.csrf import ensure_csrf_cookie
from django.views.decorators.http import require_POST

from hrc.cases import services as case_services
from hrc.cases.forms import CycleForm
from hrc.engine.startdata import defaults_of
from hrc.errors import Invalid
from hrc.live import selectors
from hrc.live.selectors import Access
from hrc.navigation import current_membership
from hrc.organisations.selectors import cells_of
from hrc.patterns.models import PatternVersion
from hrc.patterns.selectors import versions_startable_at


@login_required
@ensure_csrf_cookie
def tablet(request: HttpRequest, cell: str = "") -> HttpResponse:
    access = _access(request)
    if not selectors.is_cell(access.organisation_id, cell):
        return _unknown_cell(request, access, cell)
    context = {
        "config": _config(access, cell),
        "cell": cell,
        "cycles": _cycles(request, access, cell) if cell else [],
        "started": request.GET.get("started", ""),
        # A STOP names its cell: the whole floor's tablet sends people to theirs.
        "cells": [] if cell else cells_of(access.organisation_id),
    }
    return render(request, "tablet/tablet.html", context)


@login_required
@require_POST
def start_cycle(request: HttpRequest, cell: str, version: str) -> HttpResponse:
    """Starts a case of the version from the cell's tablet, as its start rights allow; a refusal
    shows on the tablet at its field and starts nothing."""
    access = _access(request)
    if not selectors.is_cell(access.organisation_id, cell):
        return _unknown_cell(request, access, cell)
    chosen = _startable(request, access, cell).get(int(version))
    if chosen is None:
        raise Http404("This tablet offers no such version to start.")
    form = CycleForm(
        request.POST, data_defaults=defaults_of(chosen.document), prefix=f"v{chosen.pk}"
    )
    if form.is_valid():
        try:
            case = case_services.start_case(
                chosen,
                started_by=_user(request),
                data=form.start_data(),
                reference=form.cleaned_data["reference"],
            )
        except Invalid as invalid:
            form.refuse(invalid)
        else:
            address = reverse("tablet-cell", args=[cell])
            return redirect(f"{address}?organisation={access.organisation_id}&started={case.pk}")
    cycles = [
        (v, form if v.pk == chosen.pk else _cycle_form(v))
        for v in _startable(request, access, cell).values()
    ]
    context = {
        "config": _config(access, cell),
        "cell": cell,
        "cycles": cycles,
        "refused": chosen.pk,
    }
    return render(request, "tablet/tablet.html", context, status=400)


def _access(request: HttpRequest) -> Access:
    raw = request.GET.get("organisation", "")
    if raw and not (raw.isascii() and raw.isdigit()):  # isdigit() alone takes "²"
        raise PermissionDenied("organisation must be an id.")
    if not raw:
        # The organisation the person works in (the header's switcher), else their first.
        membership = current_membership(request)
        raw = str(membership.organisation_id) if membership is not None else ""
    access = selectors.access_of(request.user, int(raw) if raw else None)
    if access is None:
        raise PermissionDenied("The tablet is for members of an organisation.")
    return access


def _config(access: Access, cell: str) -> dict[str, Any]:
    """What the tablet script needs: whose tablet, which cell, where its live socket is."""
    return {
        "organisation": access.organisation_id,
        "cell": cell,
        "user": access.user_id,
        "socket": f"/ws/live/?organisation={access.organisation_id}&cell={cell}",
    }


def _unknown_cell(request: HttpRequest, access: Access, cell: str) -> HttpResponse:
    context = {
        "cell": cell,
        "cells": cells_of(access.organisation_id),
        "organisation": selectors.organisation_name(access.organisation_id),
    }
    return render(request, "tablet/unknown_cell.html", context, status=404)


def _startable(request: HttpRequest, access: Access, cell: str) -> dict[int, PatternVersion]:
    return {
        version.pk: version
        for version in versions_startable_at(request.user, cell)
        if version.pattern.organisation_id == access.organisation_id
    }


def _cycles(request: HttpRequest, access: Access, cell: str) -> list[tuple[PatternVersion, Any]]:
    return [(v, _cycle_form(v)) for v in _startable(request, access, cell).values()]


def _cycle_form(version: PatternVersion) -> CycleForm:
    return CycleForm(data_defaults=defaults_of(version.document), prefix=f"v{version.pk}")


def _user(request: HttpRequest) -> User:
    assert isinstance(request.user, User)  # login_required
    return request.user
