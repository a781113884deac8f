"""Patterns: CRUD of drafts, check, publish, versions, import and export; the editor's helpers.

The editor's helpers (check-document, layout, execution-net) take an unsaved
`hrc-pattern/1` document in the body and store nothing. They, check, import
and publish are for the people who edit patterns, engineers and admins, and
each holds one of the organisation's engine slots while the engine works
(hrc.patterns.checking): a 429 when they are all taken.

Every queryset starts from the selectors, which see only the user's
organisations: an outsider gets 404, a user without membership an empty list.
"""

import json
import re
from functools import partial
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
from rest_framework.exceptions import PermissionDenied
from rest_framework.request import Request
from rest_framework.response import Response
from rest_framework.views import APIView

from hrc.api.exceptions import Rejected
from hrc.api.negotiation import FormatParameterForViews
from hrc.api.parsers import (
    LimitedJSONParser,
    TextXMLParser,
    XMLBodyParser,
    parse_json_body,
    read_body,
)
from hrc.api.permissions import MembersReadWritersWrite, target_organisation
from hrc.errors import NotFound
from hrc.organisations.selectors import writable_organisations
from hrc.patterns import services
from hrc.patterns.api.serializers import (
    CheckReportSerializer,
    DocumentErrorSerializer,
    ExecutionNetSerializer,
    PatternSerializer,
    PatternSummarySerializer,
    PatternVersionSerializer,
    PatternVersionSummarySerializer,
    PredictionSerializer,
    PredictRequestSerializer,
    PublishRefusedSerializer,
    StartRightsSerializer,
    SwitchSerializer,
)
from hrc.patterns.checking import checked, engine_slot, interactive_budget
from hrc.patterns.choices import DocumentFormat
from hrc.patterns.documents import (
    FormatError,
    execution_net,
    from_bpmn,
    from_pnml,
    laid_out,
    looks_like_bpmn,
    read_draft,
    to_bpmn,
    to_pnml,
)
from hrc.patterns.models import PatternModel, PatternVersion
from hrc.patterns.prediction import Measured, Options, measured_for, predict_document
from hrc.patterns.selectors import (
    patterns_visible_to,
    published_pattern_named,
    versions_of,
    versions_startable_at,
    versions_visible_to,
)

XML_MEDIA_TYPES = ("application/xml", "text/xml")
ID_PATTERN = re.compile(r"[0-9]{1,18}")  # fits a bigint primary key

FORMAT_PARAMETER = OpenApiParameter(
    "format",
    str,
    enum=list(DocumentFormat.values),
    description="json: hrc-pattern/1 (default); pnml: PNML XML; bpmn: BPMN 2.0 XML.",
)
DOCUMENT_REQUEST = {"application/json": OpenApiTypes.OBJECT}
DOCUMENT_REFUSED = OpenApiResponse(
    DocumentErrorSerializer, description="The body is not a readable hrc-pattern/1 document."
)
IMPORT_REFUSED = OpenApiResponse(
    DocumentErrorSerializer,
    description="The body cannot be imported: a JSON body is not a readable hrc-pattern/1 "
    "document; a PNML or BPMN file is named as such (`The BPMN file cannot be imported: ...`).",
)
EXPORT_RESPONSES = {
    (200, "application/json"): OpenApiTypes.OBJECT,
    (200, "application/xml"): OpenApiTypes.STR,
    400: OpenApiResponse(description="Unknown format."),
}


DRAFT_WRITE_RESPONSES = {200: PatternSerializer, 400: DocumentErrorSerializer}


class EditorsOfPatterns(MembersReadWritersWrite):
    """MembersReadWritersWrite, whose refusal names the actions that are for editors only."""

    message = (
        "Only engineers and admins of the organisation may change, check, lay out, import "
        "or publish patterns."
    )


class WritersOfThePattern(MembersReadWritersWrite):
    """MembersReadWritersWrite for a version, whose organisation is its pattern's."""

    def has_object_permission(self, request: Request, view: APIView, obj: Any) -> bool:
        return super().has_object_permission(request, view, obj.pattern)


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

    permission_classes = [EditorsOfPatterns]
    content_negotiation_class = FormatParameterForViews

    def get_queryset(self) -> QuerySet[PatternModel]:
        return patterns_visible_to(self.request.user).order_by("name", "id")

    def initial(self, request: Request, *args: Any, **kwargs: Any) -> None:
        if self.action == "import_document":
            # The import reads the raw body itself. Read it now, before a signed-in
            # browser's CSRF check makes DRF parse it and leave nothing to read.
            read_body(request._request)
        super().initial(request, *args, **kwargs)

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
        services.delete_pattern(instance)

    @extend_schema(request=None, responses={200: CheckReportSerializer})
    @action(detail=True, methods=["post"])
    def check(self, request: Request, pk: str | None = None) -> Response:
        """Checks the draft with the engine: rules, pattern classification, soundness.

        Soundness is decided within a few seconds; past them the report says the
        model is too large to decide (a `state-space-too-large` warning).
        """
        pattern = self.get_object()
        with engine_slot(pattern.organisation_id):
            return Response(checked(pattern.draft, interactive_budget()))

    @extend_schema(
        request=None, responses={201: PatternVersionSerializer, 400: PublishRefusedSerializer}
    )
    @action(detail=True, methods=["post"])
    def publish(self, request: Request, pk: str | None = None) -> Response:
        """Publishes the draft as the next version; refused with the report unless valid and sound."""
        pattern = self.get_object()
        with engine_slot(pattern.organisation_id):
            version = services.publish_pattern(pattern, published_by=_user(request))
        return Response(PatternVersionSerializer(version).data, status=status.HTTP_201_CREATED)

    @extend_schema(request=SwitchSerializer, responses=PatternSerializer)
    @action(detail=True, methods=["post"])
    def archive(self, request: Request, pk: str | None = None) -> Response:
        """`{"on": true}` archives the pattern (listed only on request), false brings it back."""
        pattern = self.get_object()
        body = SwitchSerializer(data=request.data)
        body.is_valid(raise_exception=True)
        services.archive_pattern(pattern, archived=body.validated_data["on"])
        return Response(PatternSerializer(pattern).data)

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
        responses={201: PatternSerializer, 400: IMPORT_REFUSED},
    )
    @action(
        detail=False, methods=["post"], url_path="import", url_name="import",
        parser_classes=[LimitedJSONParser, XMLBodyParser, TextXMLParser],
    )  # fmt: skip
    def import_document(self, request: Request) -> Response:
        """Creates a pattern from an hrc-pattern/1 document, a PNML file or a BPMN 2.0 file.

        The format is `?format=`, or else follows the content type: XML is BPMN when
        its root is BPMN's `<definitions>`, PNML otherwise. PNML and BPMN models are
        laid out in their actors' lanes unless they bring a position for every node.
        A file that cannot be read, or a BPMN feature the mapping does not cover, is a
        400 naming the file's format and the elements (`The PNML file cannot be imported:
        ...`), and nothing is created.
        """
        organisation = target_organisation(request, _id_param(request, "organisation"))
        xml_body = (request.content_type or "").split(";")[0].strip() in XML_MEDIA_TYPES
        body = read_body(request._request)
        default = DocumentFormat.JSON
        if xml_body:
            default = DocumentFormat.BPMN if looks_like_bpmn(body) else DocumentFormat.PNML
        document_format = _format_param(request, default)
        with engine_slot(organisation.pk):
            if document_format == DocumentFormat.PNML:
                document: object = from_pnml(body)
            elif document_format == DocumentFormat.BPMN:
                document = from_bpmn(body, partial(published_pattern_named, organisation))
            else:
                document = parse_json_body(body)
            pattern = services.import_pattern(
                organisation, document=document, created_by=_user(request)
            )
        return Response(PatternSerializer(pattern).data, status=status.HTTP_201_CREATED)

    @extend_schema(parameters=[FORMAT_PARAMETER], responses=EXPORT_RESPONSES)
    @action(detail=True, methods=["get"])
    def export(self, request: Request, pk: str | None = None) -> HttpResponse:
        """The draft as a file: hrc-pattern/1 JSON, PNML or BPMN 2.0 (with a diagram)."""
        pattern = self.get_object()
        return _export(pattern.draft, slugify(pattern.name) or "pattern", _format_param(request))

    # The editor's helpers: a document in, an answer out, nothing stored.

    @extend_schema(
        request=DOCUMENT_REQUEST, responses={200: CheckReportSerializer, 400: DOCUMENT_REFUSED}
    )
    @action(detail=False, methods=["post"], url_path="check-document", url_name="check-document")
    def check_document(self, request: Request) -> Response:
        """Checks an unsaved hrc-pattern/1 document: the same report as POST /patterns/{id}/check/.

        The editor calls this as the model changes. A body that is not a readable
        hrc-pattern/1 document is a 400 listing what is wrong with its shape.
        """
        document = request.data
        read_draft(document)  # a shape error is the request's fault: 400
        with engine_slot(_editing_organisation(request)):
            return Response(checked(document, interactive_budget()))

    @extend_schema(
        request=DOCUMENT_REQUEST,
        responses={
            200: OpenApiResponse(
                OpenApiTypes.OBJECT,
                description=(
                    "The document with `layout: {x, y}` (centres, pixels) on every place and "
                    "transition and `layout: {lanes: [{actor, y, height}], width, height, sizes}` "
                    "on the document; nothing else changed."
                ),
            ),
            400: DOCUMENT_REFUSED,
        },
    )
    @action(detail=False, methods=["post"])
    def layout(self, request: Request) -> Response:
        """Lays the document out: left to right by precedence, each actor's tasks in its lane."""
        with engine_slot(_editing_organisation(request)):
            return Response(laid_out(request.data))

    @extend_schema(
        request=DOCUMENT_REQUEST,
        responses={
            200: ExecutionNetSerializer,
            400: OpenApiResponse(
                DocumentErrorSerializer,
                description="Not a readable document, or a structural rule is broken (the issues).",
            ),
        },
    )
    @action(detail=False, methods=["post"], url_path="execution-net", url_name="execution-net")
    def execution_net(self, request: Request) -> Response:
        """The execution net the token game plays: the net the check explores and cases fire.

        Every task is split into `start:<task>` and `complete:<task>` around a
        `running:<task>` place; a time constraint adds a place from one task's
        completion to the other's start, a func constraint two; silent steps stay
        one transition. Each place and transition says which element of the
        pattern it belongs to (see hrc/engine/tokengame.py). A document that breaks
        a structural rule has no execution net: 400 with the rules' issues.
        """
        with engine_slot(_editing_organisation(request)):
            net = execution_net(request.data)
        return Response(net)

    @extend_schema(
        request=PredictRequestSerializer,
        responses={
            200: PredictionSerializer,
            400: OpenApiResponse(
                DocumentErrorSerializer,
                description="Not a readable document, a structural rule broken (the issues), "
                "or a bad option (`fields` names it).",
            ),
            404: OpenApiResponse(
                description="The pattern or version is not in your organisations."
            ),
        },
    )
    @action(detail=False, methods=["post"])
    def predict(self, request: Request) -> Response:
        """Predicts the document by simulating many cases: cycle time, each actor's load and
        waiting, the bottleneck and the typical case's critical path.

        Task times are the options' `durations`, else the times measured in `pattern`'s
        earlier versions' completed cases (by task id, else label), else the program's
        simulated time for a cobot's or device's task, else a default; `durations` in the
        answer says which, per task. With `compare_version`, that version is predicted the
        same way, side by side. Nothing is stored.
        """
        body = PredictRequestSerializer(data=request.data)
        body.is_valid(raise_exception=True)
        data = body.validated_data
        options: Options = Options(**data.get("options", {}))
        pattern = _editable(patterns_visible_to(request.user), request, data.get("pattern"))
        version = _editable(
            versions_visible_to(request.user), request, data.get("compare_version"), "pattern__"
        )
        organisation = pattern.organisation_id if pattern else _editing_organisation(request)
        with engine_slot(organisation):
            draft = predict_document(data["document"], options, _measured(pattern, options))
            compared = None
            if version is not None:
                measured = _measured(version.pattern, options)
                predicted = predict_document(version.document, options, measured, compared=True)
                number = {"id": version.pk, "number": version.number, "pattern": version.pattern_id}
                compared = {"version": number, **predicted.as_dict()}
        return Response({**draft.as_dict(), "compared": compared})


class PatternVersionViewSet(viewsets.ReadOnlyModelViewSet[PatternVersion]):
    """Published versions of your organisations' patterns. The document is immutable; engineers and
    admins set who may start its cases and retire it."""

    content_negotiation_class = FormatParameterForViews
    permission_classes = [WritersOfThePattern]

    def get_queryset(self) -> QuerySet[PatternVersion]:
        versions = versions_visible_to(self.request.user).order_by("pattern_id", "-number")
        pattern = _id_param(self.request, "pattern")
        return versions if pattern is None else versions.filter(pattern_id=pattern)

    def get_serializer_class(self) -> type[serializers.BaseSerializer[PatternVersion]]:
        if self.action == "list":
            return PatternVersionSummarySerializer
        return PatternVersionSerializer

    @extend_schema(
        parameters=[
            OpenApiParameter("pattern", int, description="Only this pattern's versions."),
            OpenApiParameter(
                "startable_at",
                str,
                description="Only the versions you may start at this cell's tablet.",
            ),
        ]
    )
    def list(self, request: Request, *args: Any, **kwargs: Any) -> Response:
        cell = request.query_params.get("startable_at")
        if cell is not None:
            startable = versions_startable_at(request.user, cell)
            return Response(PatternVersionSummarySerializer(startable, many=True).data)
        return super().list(request, *args, **kwargs)

    @extend_schema(request=StartRightsSerializer, responses=PatternVersionSerializer)
    @action(detail=True, methods=["put"], url_path="start-rights")
    def start_rights(self, request: Request, pk: str | None = None) -> Response:
        """Sets the roles that may start the version's cases and the cells whose tablets offer it."""
        version = self.get_object()
        body = StartRightsSerializer(data=request.data)
        body.is_valid(raise_exception=True)
        services.set_start_rights(
            version, roles=body.validated_data["roles"], cells=body.validated_data["cells"]
        )
        return Response(PatternVersionSerializer(version).data)

    @extend_schema(request=SwitchSerializer, responses=PatternVersionSerializer)
    @action(detail=True, methods=["post"])
    def retire(self, request: Request, pk: str | None = None) -> Response:
        """`{"on": true}` retires the version (no new cases; running ones go on), false puts it back."""
        version = self.get_object()
        body = SwitchSerializer(data=request.data)
        body.is_valid(raise_exception=True)
        services.retire_version(version, retired=body.validated_data["on"])
        return Response(PatternVersionSerializer(version).data)

    @extend_schema(parameters=[FORMAT_PARAMETER], responses=EXPORT_RESPONSES)
    @action(detail=True, methods=["get"])
    def export(self, request: Request, pk: str | None = None) -> HttpResponse:
        """The version's document as a file: hrc-pattern/1 JSON, PNML or BPMN 2.0 (with a diagram)."""
        version = self.get_object()
        filename = f"{slugify(version.pattern.name) or 'pattern'}-v{version.number}"
        return _export(version.document, filename, _format_param(request))


def _export(document: object, filename: str, document_format: str) -> HttpResponse:
    if document_format == DocumentFormat.PNML:
        response = HttpResponse(to_pnml(document), content_type="application/xml; charset=utf-8")
        extension = "pnml"
    elif document_format == DocumentFormat.BPMN:
        try:
            text = to_bpmn(document)
        except FormatError as exc:
            raise Rejected(
                {
                    "detail": f"The model cannot be exported as BPMN: {exc}",
                    "errors": [issue.as_dict() for issue in exc.issues],
                }
            ) from None
        response = HttpResponse(text, content_type="application/xml; charset=utf-8")
        extension = "bpmn"
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
        *others, last = DocumentFormat.values
        allowed = f"{', '.join(others)} or {last}"
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


def _editing_organisation(request: Request) -> int:
    """The organisation whose slots an unsaved document's engine work takes: the user's first
    organisation with an editor's role (the permission has made sure there is one)."""
    organisation_id: int | None = (
        writable_organisations(request.user).order_by("pk").values_list("pk", flat=True).first()
    )
    if organisation_id is None:
        raise PermissionDenied(EditorsOfPatterns.message)
    return organisation_id


def _editable(objects: QuerySet[Any], request: Request, pk: int | None, path: str = "") -> Any:
    """The pattern or version `pk` of an organisation where the user edits (their measurements
    are for engineers and admins); None for no pk; NotFound outside them."""
    if pk is None:
        return None
    found = objects.filter(
        pk=pk, **{f"{path}organisation__in": writable_organisations(request.user)}
    ).first()
    if found is None:
        raise NotFound("Not found.")
    return found


def _measured(pattern: PatternModel | None, options: Options) -> Measured | None:
    return measured_for(pattern) if pattern is not None and options.measured else None


def _user(request: Request) -> Any:
    """The signed-in user; the permission classes have made sure there is one."""
    return request.user
