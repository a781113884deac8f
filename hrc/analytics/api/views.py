"""Analytics over HTTP: a version's figures, a case's Gantt chart, cases as an XES log.

Behind the organisation wall (another organisation's version or case is a 404
whatever its id) and for engineers and admins: an operator of the organisation
gets 403. Everything here only reads. A bad query parameter is a 400 whose
detail names it.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

from django.db.models import QuerySet
from django.http import StreamingHttpResponse
from django.utils import timezone
from django.utils.text import slugify
from drf_spectacular.types import OpenApiTypes
from drf_spectacular.utils import OpenApiParameter, OpenApiResponse, extend_schema
from rest_framework.exceptions import NotFound, PermissionDenied
from rest_framework.negotiation import BaseContentNegotiation
from rest_framework.parsers import BaseParser
from rest_framework.renderers import BaseRenderer
from rest_framework.request import Request
from rest_framework.response import Response
from rest_framework.views import APIView

from hrc.analytics import params, selectors
from hrc.analytics.api.serializers import (
    GanttSerializer,
    VersionAnalyticsSerializer,
    VersionReport,
)
from hrc.analytics.streaming import streamed
from hrc.api.exceptions import Rejected
from hrc.cases.api.serializers import RefusalSerializer
from hrc.cases.models import Case
from hrc.organisations.selectors import AnyUser, may_write_in
from hrc.patterns.models import PatternVersion

ANALYSTS_ONLY = "Only engineers and admins of the organisation see its analytics."
REFUSALS = {400: RefusalSerializer, 403: RefusalSerializer, 404: RefusalSerializer}
XES_MEDIA_TYPE = "application/xml"

SINCE = OpenApiParameter(
    "since",
    OpenApiTypes.DATETIME,
    description="Only cases that started at or after this (ISO 8601; a date means its midnight).",
)
UNTIL = OpenApiParameter(
    "until", OpenApiTypes.DATETIME, description="Only cases that started before this."
)


def analysed_version(user: AnyUser, pk: int) -> PatternVersion:
    """The version if the user may see its analytics: 404 behind the wall, 403 for operators."""
    version = selectors.version_visible_to(user, pk)
    if version is None:
        raise NotFound("No such version.")
    if not may_write_in(user, version.pattern.organisation_id):
        raise PermissionDenied(ANALYSTS_ONLY)
    return version


def analysed_case(user: AnyUser, pk: int) -> Case:
    case = selectors.case_visible_to(user, pk)
    if case is None:
        raise NotFound("No such case.")
    if not may_write_in(user, case.organisation_id):
        raise PermissionDenied(ANALYSTS_ONLY)
    return case


class VersionAnalyticsView(APIView):
    @extend_schema(
        parameters=[SINCE, UNTIL],
        responses={200: VersionAnalyticsSerializer, **REFUSALS},
    )
    def get(self, request: Request, pk: int) -> Response:
        """A published version's cases measured: cycle time per case and per task (p50, p90,
        p99), operator waiting time, cobot utilisation, interruptions.

        Cobot utilisation is the time the version's jobs kept a cobot busy (overlapping
        jobs once) over the observed window: the first analysed case's start to the last
        one's end, or now while one runs.
        """
        version = analysed_version(request.user, pk)
        since, until = params.window(
            request.query_params.get("since"), request.query_params.get("until")
        )
        figures = selectors.version_analytics(version, now=timezone.now(), since=since, until=until)
        report = VersionReport(version, since, until, figures)
        return Response(VersionAnalyticsSerializer(report).data)


class CaseGanttView(APIView):
    @extend_schema(responses={200: GanttSerializer, **REFUSALS})
    def get(self, request: Request, pk: int) -> Response:
        """The case as a Gantt chart: a row per actor with a bar per work item (offered,
        started, ended), arrows for the constraints between the bars of their tasks, and the
        interruptions of cobot tasks."""
        case = analysed_case(request.user, pk)
        gantt = selectors.case_gantt(case, now=timezone.now())
        return Response(GanttSerializer(gantt).data)


class JsonForRefusals(BaseContentNegotiation):
    """The download's refusals are JSON whatever the client accepts (a mining tool may ask
    for XML only, and should learn why, not get a 406); the log is not rendered by DRF."""

    def select_renderer(
        self,
        request: Request,
        renderers: Iterable[BaseRenderer],
        format_suffix: str | None = None,
    ) -> tuple[BaseRenderer, str]:
        renderer = next(iter(renderers))  # JSON, the first of the default renderers
        return renderer, renderer.media_type

    def select_parser(self, request: Request, parsers: Iterable[BaseParser]) -> BaseParser | None:
        return next(iter(parsers), None)  # GET only: nothing is parsed


class XesExportView(APIView):
    content_negotiation_class = JsonForRefusals

    @extend_schema(
        parameters=[
            OpenApiParameter("version", int, description="The cases of this published version."),
            OpenApiParameter("case", int, description="This case (of `version`, when both)."),
            OpenApiParameter(
                "lifecycle",
                str,
                enum=["pairs", "full"],
                description="pairs (default): start and complete of each task; full: also "
                "schedule, assign, reassign, suspend, resume, withdraw and ate_abort.",
            ),
            SINCE,
            UNTIL,
        ],
        responses={
            (200, XES_MEDIA_TYPE): OpenApiResponse(
                OpenApiTypes.STR, description="An XES (IEEE 1849-2016) log, a trace per case."
            ),
            **REFUSALS,
        },
    )
    def get(self, request: Request) -> StreamingHttpResponse:
        """Cases as an XES event log for process-mining tools, streamed as a download.

        One trace per case (concept:name is the case id), its task events in the log's
        order with concept:name (the task's label), lifecycle:transition, time:timestamp,
        org:resource (user or cobot) and org:role (the pattern actor). Say `version`,
        `case` or both.
        """
        query = request.query_params
        version_id = params.identifier("version", query.get("version"))
        case_id = params.identifier("case", query.get("case"))
        lifecycle = params.lifecycle(query.get("lifecycle"))
        since, until = params.window(query.get("since"), query.get("until"))
        if version_id is None and case_id is None:
            raise Rejected(
                {"detail": "Say which cases: version or case (an id).", "parameter": "version"}
            )
        selection = _selection(request.user, version_id, case_id, since, until)
        return streamed(
            request._request,
            selectors.xes_log(selection, lifecycle),
            content_type=f"{XES_MEDIA_TYPE}; charset=utf-8",
            filename=selection.filename,
        )


def _selection(
    user: AnyUser, version_id: int | None, case_id: int | None, since: Any, until: Any
) -> selectors.LogSelection:
    version = analysed_version(user, version_id) if version_id is not None else None
    case = analysed_case(user, case_id) if case_id is not None else None
    if case is not None:
        if version is not None and case.version_id != version.pk:
            raise Rejected(
                {
                    "detail": f"Case {case.pk} is not a case of version {version.pk}.",
                    "parameter": "case",
                }
            )
        cases: QuerySet[Case] = Case.objects.filter(pk=case.pk)
        version = case.version
        name = f"{version.pattern.name} v{version.number}, case {case.pk}"
        filename = f"{slugify(version.pattern.name) or 'pattern'}-v{version.number}-case-{case.pk}"
    else:
        assert version is not None  # one of the two was given
        cases = selectors.cases_of(version, since=since, until=until)
        name = f"{version.pattern.name} v{version.number}"
        filename = f"{slugify(version.pattern.name) or 'pattern'}-v{version.number}"
    return selectors.LogSelection(cases, name, f"{filename}.xes")
