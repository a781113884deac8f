"""The analytics pages: the versions with cases, one version's figures, one case's Gantt chart.

Server-rendered (the chart is an SVG drawn by hrc.analytics.gantt), for
engineers and admins behind the organisation wall like the supervisor pages:
another organisation's version or case is a 404, an operator gets 403 (a
refusal of hrc.errors, which hrc.middleware.RefusalMiddleware renders). The
XES download is the API's (/api/analytics/xes/), which the session signs in to.
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass
from urllib.parse import urlencode

from django.contrib.auth.decorators import login_required
from django.http import Http404, HttpRequest, HttpResponse
from django.shortcuts import render
from django.urls import reverse
from django.utils import timezone

from hrc.analytics import params, selectors
from hrc.analytics.gantt import ConstraintRow, draw_gantt
from hrc.cases.models import Case
from hrc.errors import NotAllowed
from hrc.organisations.selectors import may_write_in, writable_organisations
from hrc.patterns.models import PatternVersion

ANALYSTS_ONLY = "Only engineers and admins of the organisation see its analytics."
GANTT_WIDTH = 1200
# The arrowheads' colours; the arrows' own are in templates/analytics/_analytics_head.html.
ARROW_COLOURS = (("time", "#8250df"), ("space", "#bf8700"), ("func", "#0969da"))


@dataclass(frozen=True)
class ConstraintLine:
    row: ConstraintRow
    arrows: int


@login_required
def version_list(request: HttpRequest) -> HttpResponse:
    """The published versions of the user's organisations, those with cases first."""
    if not writable_organisations(request.user).exists():
        raise NotAllowed(ANALYSTS_ONLY)
    versions = selectors.analysed_versions(request.user)
    return render(request, "analytics/version_list.html", {"versions": versions})


@login_required
def version_detail(request: HttpRequest, pk: int) -> HttpResponse:
    """One version's figures: cycle times, tasks, operator waiting, cobots, interruptions;
    `?since=` and `?until=` narrow them to the cases that started in between."""
    version = _analysed_version(request, pk)
    since, until = params.window(request.GET.get("since"), request.GET.get("until"))
    now = timezone.now()
    figures = selectors.version_analytics(version, now=now, since=since, until=until)
    window = {key: value for key, value in (("since", since), ("until", until)) if value}
    xes_query = {"version": version.pk, **{k: v.isoformat() for k, v in window.items()}}
    context = {
        "version": version,
        "figures": figures,
        "since": request.GET.get("since", ""),
        "until": request.GET.get("until", ""),
        "filtered": bool(window),
        "xes_url": f"{reverse('analytics-xes')}?{urlencode(xes_query)}",
        "api_url": reverse("analytics-version", args=[version.pk]),
    }
    return render(request, "analytics/version_detail.html", context)


@login_required
def case_gantt(request: HttpRequest, pk: int) -> HttpResponse:
    """One case as a Gantt chart, with its bars as a table below."""
    case = _analysed_case(request, pk)
    drawing = draw_gantt(selectors.case_gantt(case, now=timezone.now()), width=GANTT_WIDTH)
    rows = sorted(drawing.bars, key=lambda b: (b.bar.offered_at, b.bar.work_item))
    arrows = Counter(arrow.constraint for arrow in drawing.gantt.arrows)
    context = {
        "case": case,
        "drawing": drawing,
        "bar_rows": rows,
        "constraint_rows": [ConstraintLine(c, arrows[c.index]) for c in drawing.gantt.constraints],
        "arrow_colours": ARROW_COLOURS,
        "xes_url": f"{reverse('analytics-xes')}?{urlencode({'case': case.pk})}",
        "api_url": reverse("analytics-case-gantt", args=[case.pk]),
    }
    return render(request, "analytics/case_gantt.html", context)


def _analysed_version(request: HttpRequest, pk: int) -> PatternVersion:
    version = selectors.version_visible_to(request.user, pk)
    if version is None:
        raise Http404("No such version.")
    if not may_write_in(request.user, version.pattern.organisation_id):
        raise NotAllowed(ANALYSTS_ONLY)
    return version


def _analysed_case(request: HttpRequest, pk: int) -> Case:
    case = selectors.case_visible_to(request.user, pk)
    if case is None:
        raise Http404("No such case.")
    if not may_write_in(request.user, case.organisation_id):
        raise NotAllowed(ANALYSTS_ONLY)
    return case
