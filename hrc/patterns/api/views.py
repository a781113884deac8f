"""Patterns: CRUD of drafts, check, publish, versions, import and export.

Every queryset starts from the selectors, which see only the user's
organisations: an outsider gets 404, a user without membership an empty list.
"""

import json
import re
from typing import Any

from django.db.models import QuerySet
from django.http import HttpResponse
from django.utils.text import slugify
from drf_spectacular.types import OpenApiTypes
from drf_spectacular.utils import (
    OpenApiParameter,
    OpenApiResponse,
    extend_schema,
    extend_schema_view,
)
from rest_framework import serializers, status, viewsets
from rest_framework.decorators import action
from rest_framework.request import Request
from rest_framework.response import Response

from hrc.api.exceptions import Rejected
from hrc.api.negotiation import FormatParameterForViews
from hrc.api.parsers import parse_json_body, read_body
from hrc.api.permissions import MembersReadWritersWrite, target_organisation
from hrc.patterns import services
from hrc.patterns.api.serializers import (
    CheckReportSerializer,
    DocumentErrorSerializer,
    PatternSerializer,
    PatternSummarySerializer,
    PatternVersionSerializer,
    PatternVersionSummarySerializer,
    PublishRefusedSerializer,
)
from hrc.patterns.choices import DocumentFormat
from hrc.patterns.documents import check_report, from_pnml, to_pnml
from hrc.patterns.models import PatternModel, PatternVersion
from hrc.patterns.selectors import patterns_visible_to, versions_of, versions_visible_to

XML_MEDIA_TYPES = ("application/xml", "text/xml")
ID_PATTERN = re.compile(r"[0-9]{1,18}")  # fits a bigint primary key

FORMAT_PARAMETER = OpenApiParameter(
    "format",
    str,
    enum=list(DocumentFormat.values),
    description="json: hrc-pattern/1 (default); pnml: PNML XML.",
)
EXPORT_RESPONSES = {
    (200, "application/json"): OpenApiTypes.OBJECT,
    (200, "application/xml"): OpenApiTypes.STR,
    400: OpenApiResponse(description="Unknown format."),
}


DRAFT_WRITE_RESPONSES = {200: PatternSerializer, 400: DocumentErrorSerializer}


@extend_schema_view(
    create=extend_schema(responses={201: PatternSerializer, 400: DocumentErrorSerializer}),
    update=extend_schema(responses=DRAFT_WRITE_RESPONSES),
    partial_update=extend_schema(responses=DRAFT_WRITE_RESPONSES),
    destroy=extend_schema(
        responses={
            204: OpenApiResponse(description="Deleted."),
            409: OpenApiResponse(description="The pattern has published versions; it is kept."),
        }
    ),
)
class PatternViewSet(viewsets.ModelViewSet[PatternModel]):
    """Collaboration patterns of your organisations. Members read; engineers and admins write."""

    permission_classes = [MembersReadWritersWrite]
    content_negotiation_class = FormatParameterForViews
    # POSTs that change nothing: operators may run them too.
    read_actions = frozenset({"check"})

    def get_queryset(self) -> QuerySet[PatternModel]:
        return patterns_visible_to(self.request.user).order_by("name", "id")

    def get_serializer_class(self) -> type[serializers.BaseSerializer[PatternModel]]:
        return PatternSummarySerializer if self.action == "list" else PatternSerializer

    def perform_create(self, serializer: serializers.BaseSerializer[PatternModel]) -> None:
        data = serializer.validated_data
        organisation = target_organisation(self.request, data.get("organisation"))
        serializer.instance = services.create_pattern(
            organisation,
            name=data["name"],
            description=data.get("description", ""),
            draft=data.get("draft"),
            created_by=_user(self.request),
        )

    def perform_update(self, serializer: serializers.BaseSerializer[PatternModel]) -> None:
        assert serializer.instance is not None
        data = serializer.validated_data
        services.update_pattern(
            serializer.instance,
            name=data.get("name"),
            description=data.get("description"),
            draft=data.get("draft"),
        )

    def perform_destroy(self, instance: PatternModel) -> None:
        try:
            services.delete_pattern(instance)
        except services.PatternHasVersions as exc:
            raise Rejected({"detail": str(exc)}, status.HTTP_409_CONFLICT) from None

    @extend_schema(request=None, responses={200: CheckReportSerializer})
    @action(detail=True, methods=["post"])
    def check(self, request: Request, pk: str | None = None) -> Response:
        """Checks the draft with the engine: rules, pattern classification, soundness."""
        return Response(check_report(self.get_object().draft))

    @extend_schema(
        request=None, responses={201: PatternVersionSerializer, 400: PublishRefusedSerializer}
    )
    @action(detail=True, methods=["post"])
    def publish(self, request: Request, pk: str | None = None) -> Response:
        """Publishes the draft as the next version; refused with the report unless valid and sound."""
        pattern = self.get_object()
        try:
            version = services.publish_pattern(pattern, published_by=_user(request))
        except services.PublishRefused as exc:
            raise Rejected(
                {
                    "detail": "The draft does not pass the check; see the report.",
                    "report": exc.report,
                }
            ) from None
        return Response(PatternVersionSerializer(version).data, status=status.HTTP_201_CREATED)

    @extend_schema(responses={200: PatternVersionSummarySerializer(many=True)})
    @action(detail=True, methods=["get"])
    def versions(self, request: Request, pk: str | None = None) -> Response:
        """The pattern's published versions, newest first."""
        # The viewset's model is PatternModel; this action pages another model's rows.
        page = self.paginate_queryset(versions_of(self.get_object()))  # type: ignore[arg-type]
        serializer = PatternVersionSummarySerializer(page, many=True)  # type: ignore[arg-type]
        return self.get_paginated_response(serializer.data)

    @extend_schema(
        parameters=[
            FORMAT_PARAMETER,
            OpenApiParameter(
                "organisation",
                int,
                description="Target organisation; needed only if you have several.",
            ),
        ],
        request={"application/json": OpenApiTypes.OBJECT, "application/xml": OpenApiTypes.STR},
        responses={201: PatternSerializer, 400: DocumentErrorSerializer},
    )
    @action(detail=False, methods=["post"], url_path="import", url_name="import")
    def import_document(self, request: Request) -> Response:
        """Creates a pattern from an hrc-pattern/1 document or a PNML file.

        The format is `?format=`, or else follows the content type (XML means PNML).
        """
        organisation = target_organisation(request, _id_param(request, "organisation"))
        xml_body = (request.content_type or "").split(";")[0].strip() in XML_MEDIA_TYPES
        default = DocumentFormat.PNML if xml_body else DocumentFormat.JSON
        body = read_body(request._request)
        if _format_param(request, default) == DocumentFormat.PNML:
            document: object = from_pnml(body)
        else:
            document = parse_json_body(body)
        pattern = services.import_pattern(
            organisation, document=document, created_by=_user(request)
        )
        return Response(PatternSerializer(pattern).data, status=status.HTTP_201_CREATED)

    @extend_schema(parameters=[FORMAT_PARAMETER], responses=EXPORT_RESPONSES)
    @action(detail=True, methods=["get"])
    def export(self, request: Request, pk: str | None = None) -> HttpResponse:
        """The draft as a file: hrc-pattern/1 JSON or PNML."""
        pattern = self.get_object()
        return _export(pattern.draft, slugify(pattern.name) or "pattern", _format_param(request))


class PatternVersionViewSet(viewsets.ReadOnlyModelViewSet[PatternVersion]):
    """Published versions of your organisations' patterns. Immutable: there is no write."""

    content_negotiation_class = FormatParameterForViews

    def get_queryset(self) -> QuerySet[PatternVersion]:
        versions = versions_visible_to(self.request.user).order_by("pattern_id", "-number")
        pattern = _id_param(self.request, "pattern")
        return versions if pattern is None else versions.filter(pattern_id=pattern)

    def get_serializer_class(self) -> type[serializers.BaseSerializer[PatternVersion]]:
        if self.action == "list":
            return PatternVersionSummarySerializer
        return PatternVersionSerializer

    @extend_schema(
        parameters=[OpenApiParameter("pattern", int, description="Only this pattern's versions.")]
    )
    def list(self, request: Request, *args: Any, **kwargs: Any) -> Response:
        return super().list(request, *args, **kwargs)

    @extend_schema(parameters=[FORMAT_PARAMETER], responses=EXPORT_RESPONSES)
    @action(detail=True, methods=["get"])
    def export(self, request: Request, pk: str | None = None) -> HttpResponse:
        """The version's document as a file: hrc-pattern/1 JSON or PNML."""
        version = self.get_object()
        filename = f"{slugify(version.pattern.name) or 'pattern'}-v{version.number}"
        return _export(version.document, filename, _format_param(request))


def _export(document: object, filename: str, document_format: str) -> HttpResponse:
    if document_format == DocumentFormat.PNML:
        response = HttpResponse(to_pnml(document), content_type="application/xml; charset=utf-8")
        extension = "pnml"
    else:
        text = json.dumps(document, indent=2, ensure_ascii=False)
        response = HttpResponse(text, content_type="application/json; charset=utf-8")
        extension = "json"
    response["Content-Disposition"] = f'attachment; filename="{filename}.{extension}"'
    return response


def _format_param(request: Request, default: str = DocumentFormat.JSON) -> str:
    """`?format=`, one of DocumentFormat; a 400 that lists them for anything else."""
    value = request.query_params.get("format", default)
    if value not in DocumentFormat.values:
        allowed = " or ".join(DocumentFormat.values)
        raise Rejected({"detail": f"Unknown format {value[:40]!r}: use {allowed}."})
    return value


def _id_param(request: Request, name: str) -> int | None:
    """An id in the query string; None when absent, a 400 when it is not an id."""
    value = request.query_params.get(name)
    if value is None:
        return None
    if not ID_PATTERN.fullmatch(value):
        raise Rejected({"detail": f"{name} must be an id (a whole number)."})
    return int(value)


def _user(request: Request) -> Any:
    """The signed-in user; the permission classes have made sure there is one."""
    return request.user
