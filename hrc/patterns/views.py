"""The pattern editor's pages: the organisation's patterns, a new pattern, editing one.

Behind the API's organisation wall and roles: a pattern of another
organisation is a 404 whatever its id; a member who may not write (an
operator) gets 403 on the editor. The pages only read: the editor script
(frontend/src/editor/) saves, checks and publishes through the REST API, so
the services' checks and refusal messages stay in one place.
"""

from dataclasses import dataclass
from typing import Any

from django.contrib.auth.decorators import login_required
from django.db.models import Prefetch
from django.http import HttpRequest, HttpResponse
from django.shortcuts import get_object_or_404, redirect, render
from django.urls import reverse
from django.views.decorators.csrf import ensure_csrf_cookie
from django.views.decorators.http import require_POST

from hrc.engine.taskconfig import DEVICE_CALLS
from hrc.errors import NotAllowed
from hrc.organisations.models import Organisation
from hrc.organisations.selectors import may_write_in, writable_organisations
from hrc.patterns.models import PatternModel, PatternVersion
from hrc.patterns.selectors import patterns_visible_to
from hrc.patterns.services import archive_pattern

WRITERS_ONLY = "Only engineers and admins of the organisation draw and change its patterns."


@dataclass(frozen=True)
class PatternRow:
    pattern: PatternModel
    can_edit: bool
    versions: list[PatternVersion]

    @property
    def pattern_class(self) -> list[str]:
        """The class the newest version was checked as (drafts are classified in the editor)."""
        return list(self.versions[0].report.get("patterns", [])) if self.versions else []

    @property
    def startable(self) -> PatternVersion | None:
        """The newest version in service: the one "Start a case" starts."""
        return next((v for v in self.versions if v.retired_at is None), None)


@login_required
def pattern_list(request: HttpRequest) -> HttpResponse:
    """Every pattern of the user's organisations with its class and versions; writers get "new",
    "open", "start a case" and archive. Archived patterns are listed with `?archived=1`."""
    writable = list(writable_organisations(request.user).order_by("name"))
    writable_ids = {organisation.pk for organisation in writable}
    archived = request.GET.get("archived") == "1"
    patterns = (
        patterns_visible_to(request.user)
        .filter(archived_at__isnull=not archived)
        .prefetch_related(Prefetch("versions", queryset=PatternVersion.objects.order_by("-number")))
        .order_by("organisation__name", "name", "id")
    )
    rows = [
        PatternRow(pattern, pattern.organisation_id in writable_ids, list(pattern.versions.all()))
        for pattern in patterns
    ]
    context = {"rows": rows, "writable": writable, "archived": archived}
    return render(request, "patterns/list.html", context)


@login_required
@require_POST
def pattern_archive(request: HttpRequest, pk: int) -> HttpResponse:
    """Archives a pattern (`archive=1`) or brings it back (`archive=0`), then lists the patterns."""
    pattern = get_object_or_404(patterns_visible_to(request.user), pk=pk)
    if not may_write_in(request.user, pattern.organisation_id):
        raise NotAllowed(WRITERS_ONLY)
    archive = request.POST.get("archive") == "1"
    archive_pattern(pattern, archived=archive)
    return redirect(f"{reverse('patterns:list')}{'' if archive else '?archived=1'}")


@login_required
@ensure_csrf_cookie
def pattern_new(request: HttpRequest) -> HttpResponse:
    """The editor on an empty model; it is created in `?organisation=` (or the writer's only one) when first saved."""
    organisation = _target_organisation(request)
    if organisation is None:
        raise NotAllowed(WRITERS_ONLY)
    config = {
        "pattern": {
            "id": None,
            "name": "New pattern",
            "canWrite": True,
            "organisation": organisation.pk,
        },
        "draft": None,
    }
    return _editor(request, config, f"New pattern in {organisation.name}")


@login_required
@ensure_csrf_cookie
def pattern_edit(request: HttpRequest, pk: int) -> HttpResponse:
    """The editor on a pattern's draft."""
    pattern = get_object_or_404(patterns_visible_to(request.user), pk=pk)
    if not may_write_in(request.user, pattern.organisation_id):
        raise NotAllowed(WRITERS_ONLY)
    config = {
        "pattern": {
            "id": pattern.pk,
            "name": pattern.name,
            "canWrite": True,
            "organisation": pattern.organisation_id,
            "latestVersion": getattr(pattern, "latest_version", None),
        },
        "draft": pattern.draft,
    }
    return _editor(request, config, pattern.name)


def _target_organisation(request: HttpRequest) -> Organisation | None:
    """The organisation a new pattern goes to; None when the user may write in none of those asked."""
    writable = writable_organisations(request.user)
    requested = request.GET.get("organisation", "")
    if requested.isascii() and requested.isdigit():  # isdigit() alone takes "²"
        return writable.filter(pk=int(requested)).first()
    return writable.order_by("name", "pk").first()


def _editor(request: HttpRequest, config: dict[str, Any], title: str) -> HttpResponse:
    # The device calls a cobot task can make, with their arguments: the engine's list, so
    # the properties panel offers exactly what a case can run.
    config["deviceCalls"] = {
        name: list(arguments) for name, (_, arguments, _) in DEVICE_CALLS.items()
    }
    return render(request, "patterns/editor.html", {"config": config, "title": title})
