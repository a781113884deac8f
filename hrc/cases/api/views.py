"""Running cases over HTTP: start and steer cases, the task list, incidents, cobot queues, messages.

Every queryset starts from hrc.cases.selectors, which see only the user's
organisations: an outsider gets 404 and empty lists, also on POST actions.
Roles are checked per object after that: engineers and admins start, cancel,
suspend and resume cases, resolve incidents, send messages, set actor
mappings and reassign work items; operators get 403. Work items are the services' to allow
(progress.lock_operator_item, by selectors.performable_by). The services' refusals (hrc.errors) reach the
client as 400, 403 or 409 with a `detail` (hrc.api.exceptions).
"""

import re
from collections.abc import Sequence
from typing import Any

from django.contrib.auth.models import User
from django.db.models import QuerySet
from drf_spectacular.utils import OpenApiParameter, extend_schema, extend_schema_view
from rest_framework import generics, mixins, serializers, status, viewsets
from rest_framework.decorators import action
from rest_framework.exceptions import PermissionDenied
from rest_framework.permissions import IsAuthenticated
from rest_framework.request import Request
from rest_framework.response import Response
from rest_framework.views import APIView

from hrc.api.exceptions import Rejected
from hrc.api.permissions import WRITERS_ONLY, MembersReadWritersWrite, target_organisation
from hrc.cases import selectors, services
from hrc.cases.api.serializers import (
    ActorMappingSerializer,
    CancelRequestSerializer,
    CaseEventSerializer,
    CaseSerializer,
    CaseSummarySerializer,
    CompleteRequestSerializer,
    IncidentSerializer,
    InterruptionSerializer,
    MessageRequestSerializer,
    MessageSerializer,
    PerformerSerializer,
    QueuedJobSerializer,
    ReassignRequestSerializer,
    RefusalSerializer,
    ResolveRequestSerializer,
    StartCaseRequestSerializer,
    WorkItemDetailSerializer,
    WorkItemSerializer,
)
from hrc.cases.choices import CaseStatus, WorkItemKind
from hrc.cases.messages import receive_message
from hrc.cases.models import Case, CaseEvent, Incident, Interruption, Job, WorkItem
from hrc.errors import NotFound
from hrc.organisations.choices import Role
from hrc.organisations.selectors import may_write_in, role_in
from hrc.patterns.models import PatternVersion
from hrc.patterns.selectors import versions_visible_to, why_may_not_start

ID_PATTERN = re.compile(r"[0-9]{1,18}")  # fits a bigint primary key

REFUSED_404 = {404: RefusalSerializer}
# A write by a member: wrong input, not their role, not found (or not theirs), moved on.
WRITE_REFUSALS = {
    400: RefusalSerializer,
    403: RefusalSerializer,
    404: RefusalSerializer,
    409: RefusalSerializer,
}


class WritersOfTheOrganisation(MembersReadWritersWrite):
    """MembersReadWritersWrite for rows that belong to an organisation through a case or a pattern."""

    def has_object_permission(self, request: Request, view: APIView, obj: Any) -> bool:
        owner = getattr(obj, "case", None) or getattr(obj, "pattern", None) or obj
        return super().has_object_permission(request, view, owner)


# Cases ---------------------------------------------------------------------------------


@extend_schema_view(
    list=extend_schema(
        parameters=[
            OpenApiParameter("status", str, enum=list(CaseStatus.values)),
            OpenApiParameter("version", int, description="Only cases of this published version."),
        ]
    ),
    retrieve=extend_schema(responses={200: CaseSerializer, **REFUSED_404}),
)
class CaseViewSet(mixins.ListModelMixin, mixins.RetrieveModelMixin, viewsets.GenericViewSet[Case]):
    """Cases of your organisations' published patterns. Members read; engineers and admins steer."""

    permission_classes = [WritersOfTheOrganisation]

    def get_queryset(self) -> QuerySet[Case]:
        cases = selectors.cases_visible_to(self.request.user).order_by("-started_at", "-id")
        if self.action == "retrieve":
            return selectors.with_open_work(cases, self.request.user)
        if self.action != "list":
            return cases  # the actions answer with a fresh copy (_detail)
        wanted = self.request.query_params.get("status")
        if wanted is not None:
            if wanted not in CaseStatus.values:
                allowed = ", ".join(CaseStatus.values)
                raise Rejected({"detail": f"status must be one of {allowed}."})
            cases = cases.filter(status=wanted)
        version = _id_param(self.request, "version")
        return cases if version is None else cases.filter(version_id=version)

    def get_serializer_class(self) -> type[serializers.BaseSerializer[Case]]:
        return CaseSummarySerializer if self.action == "list" else CaseSerializer

    @extend_schema(
        request=StartCaseRequestSerializer, responses={201: CaseSerializer, **WRITE_REFUSALS}
    )
    def get_permissions(self) -> Sequence[Any]:
        # Who may start a case is the version's start rights (operators too, at their cell),
        # decided in create once the version is known.
        if self.action == "create":
            return [IsAuthenticated()]
        return super().get_permissions()

    def create(self, request: Request) -> Response:
        """Starts a case of a published version: as the version's start rights allow (by default
        engineers and admins; operators at the tablet of one of its start cells)."""
        body = StartCaseRequestSerializer(data=request.data, context={"request": request})
        body.is_valid(raise_exception=True)
        version: PatternVersion = body.validated_data["version"]
        refusal = why_may_not_start(request.user, version, cell=body.validated_data["cell"])
        if refusal is not None:
            raise PermissionDenied(refusal)
        mapping = body.validated_data.get("actor_mapping")
        if mapping and role_in(request.user, version.pattern.organisation_id) == Role.OPERATOR:
            raise PermissionDenied(
                "Operators start cases with the version's mapping; leave actor_mapping out."
            )
        case = services.start_case(
            version,
            started_by=_user(request),
            actor_mapping=mapping,
            data=body.validated_data.get("data"),
            reference=body.validated_data["reference"],
        )
        return Response(self._detail(case), status=status.HTTP_201_CREATED)

    @extend_schema(
        request=CancelRequestSerializer, responses={200: CaseSerializer, **WRITE_REFUSALS}
    )
    @action(detail=True, methods=["post"])
    def cancel(self, request: Request, pk: str | None = None) -> Response:
        """Cancels the case: open work is withdrawn, queued jobs are cancelled."""
        body = CancelRequestSerializer(data=request.data)
        body.is_valid(raise_exception=True)
        reason = body.validated_data.get("reason", "")
        case = services.cancel_case(self.get_object(), by=_user(request), reason=reason)
        return Response(self._detail(case))

    @extend_schema(request=None, responses={200: CaseSerializer, **WRITE_REFUSALS})
    @action(detail=True, methods=["post"])
    def suspend(self, request: Request, pk: str | None = None) -> Response:
        """Stops offering and dispatching new work; work under way may finish."""
        case = services.suspend_case(self.get_object(), by=_user(request))
        return Response(self._detail(case))

    @extend_schema(request=None, responses={200: CaseSerializer, **WRITE_REFUSALS})
    @action(detail=True, methods=["post"])
    def resume(self, request: Request, pk: str | None = None) -> Response:
        """Offers and dispatches work again."""
        case = services.resume_case(self.get_object(), by=_user(request))
        return Response(self._detail(case))

    @extend_schema(
        parameters=[
            OpenApiParameter("after", int, description="Only the events after this `seq`.")
        ],
        responses={200: CaseEventSerializer(many=True), **REFUSED_404},
    )
    @action(detail=True, methods=["get"])
    def events(self, request: Request, pk: str | None = None) -> Response:
        """The case's event log in order (seq 1, 2, 3…); `?after=` fetches only newer events."""
        events = selectors.events_of(self.get_object(), after=_whole_param(request, "after"))
        # The viewset's model is Case; this action pages another model's rows.
        page: list[CaseEvent] = self.paginate_queryset(events)  # type: ignore[arg-type,assignment]
        return self.get_paginated_response(CaseEventSerializer(page, many=True).data)

    @extend_schema(responses={200: InterruptionSerializer(many=True), **REFUSED_404})
    @action(detail=True, methods=["get"])
    def interruptions(self, request: Request, pk: str | None = None) -> Response:
        """The case's space-constraint interruptions in the order they began, with durations."""
        interruptions = selectors.interruptions_of(self.get_object())
        page: list[Interruption] = self.paginate_queryset(interruptions)  # type: ignore[arg-type,assignment]
        return self.get_paginated_response(InterruptionSerializer(page, many=True).data)

    def _detail(self, case: Case) -> Any:
        user = self.request.user
        fresh = selectors.with_open_work(selectors.cases_visible_to(user), user).get(pk=case.pk)
        return CaseSerializer(fresh).data


# Work items ----------------------------------------------------------------------------

KIND_PARAMETER = OpenApiParameter(
    "kind",
    str,
    description="Comma-separated kinds: operator (default: the tasks you may perform), "
    "step, device (every open cobot task of your organisations, read-only).",
)
WORK_ITEM_REFUSALS = {403: RefusalSerializer, 404: RefusalSerializer, 409: RefusalSerializer}


@extend_schema_view(
    list=extend_schema(
        parameters=[
            KIND_PARAMETER,
            OpenApiParameter("case", int, description="Only this case's work items."),
        ]
    ),
    retrieve=extend_schema(responses={200: WorkItemDetailSerializer, **REFUSED_404}),
)
class WorkItemViewSet(viewsets.ReadOnlyModelViewSet[WorkItem]):
    """Your task list; any work item of your organisations by id. You act on those offered to you."""

    def get_queryset(self) -> QuerySet[WorkItem]:
        user = self.request.user
        if self.action != "list":
            return selectors.work_items_visible_to(user)
        items = selectors.task_list(user, _kinds(self.request))
        case = _id_param(self.request, "case")
        return items if case is None else items.filter(case_id=case)

    def get_serializer_class(self) -> type[serializers.BaseSerializer[WorkItem]]:
        return WorkItemSerializer if self.action == "list" else WorkItemDetailSerializer

    @extend_schema(request=None, responses={200: WorkItemDetailSerializer, **WORK_ITEM_REFUSALS})
    @action(detail=True, methods=["post"])
    def claim(self, request: Request, pk: str | None = None) -> Response:
        """Takes the task: nobody else sees it as open any more."""
        item = services.claim_work_item(_item_id(pk), user=_user(request))
        return Response(self._detail(item))

    @extend_schema(request=None, responses={200: WorkItemDetailSerializer, **WORK_ITEM_REFUSALS})
    @action(detail=True, methods=["post"])
    def unclaim(self, request: Request, pk: str | None = None) -> Response:
        """Gives a claimed, not yet started task back."""
        item = services.unclaim_work_item(_item_id(pk), user=_user(request))
        return Response(self._detail(item))

    @extend_schema(request=None, responses={200: WorkItemDetailSerializer, **WORK_ITEM_REFUSALS})
    @action(detail=True, methods=["post"])
    def start(self, request: Request, pk: str | None = None) -> Response:
        """Starts the task (claiming it if nobody has); the other tasks of a choice withdraw."""
        item = services.start_work_item(_item_id(pk), user=_user(request))
        return Response(self._detail(item))

    @extend_schema(
        request=CompleteRequestSerializer,
        responses={200: WorkItemDetailSerializer, 400: RefusalSerializer, **WORK_ITEM_REFUSALS},
    )
    @action(detail=True, methods=["post"])
    def complete(self, request: Request, pk: str | None = None) -> Response:
        """Completes the running task with its form data; a 400 names each field the form refuses."""
        body = CompleteRequestSerializer(data=request.data)
        body.is_valid(raise_exception=True)
        item = services.complete_work_item(
            _item_id(pk), user=_user(request), data=body.validated_data.get("data")
        )
        return Response(self._detail(item))

    @extend_schema(
        responses={200: PerformerSerializer(many=True), **WRITE_REFUSALS},
    )
    @action(detail=True, methods=["get"])
    def performers(self, request: Request, pk: str | None = None) -> Response:
        """Who may do an operator task, by name: whom `reassign` takes. Engineers and admins."""
        item = self._to_steer(request, pk)
        services.check_operator_task(item)
        return Response(PerformerSerializer(selectors.performers_of(item), many=True).data)

    @extend_schema(
        request=ReassignRequestSerializer,
        responses={200: WorkItemDetailSerializer, **WRITE_REFUSALS},
    )
    @action(detail=True, methods=["post"])
    def reassign(self, request: Request, pk: str | None = None) -> Response:
        """Hands a task someone holds, or an offered one, to another operator who may do it; or
        gives a claimed one back to its candidates (`user`: null). Engineers and admins: for when
        the operator who holds it has gone. A started task stays started, with its new holder."""
        item = self._to_steer(request, pk)
        organisation = item.case.organisation_id
        body = ReassignRequestSerializer(data=request.data)
        body.is_valid(raise_exception=True)
        wanted, to = body.validated_data["user"], None
        if wanted is not None:
            # Only members are found: an id from another organisation names nobody here.
            to = User.objects.filter(pk=wanted, memberships__organisation_id=organisation).first()
            if to is None:
                raise Rejected({"detail": f"There is no user {wanted} in this organisation."})
        item = services.reassign_work_item(item, by=_user(request), to=to)
        return Response(self._detail(item))

    @extend_schema(request=None, responses={200: WorkItemDetailSerializer, **WORK_ITEM_REFUSALS})
    @action(detail=True, methods=["post"], url_path="left-area")
    def left_area(self, request: Request, pk: str | None = None) -> Response:
        """Says the operator of a cancelled task has left its shared area: the cobots that
        operator's presence paused or slowed resume. Its operator, or an engineer or admin of
        the organisation; a second confirmation changes nothing."""
        item = selectors.work_items_visible_to(request.user).filter(pk=_item_id(pk)).first()
        if item is None:
            raise NotFound(f"There is no work item {pk} in your organisations.")
        if item.claimed_by_id != request.user.pk and not may_write_in(
            request.user, item.case.organisation_id
        ):
            raise PermissionDenied("Only its operator or a supervisor may say the area is clear.")
        services.confirm_left_area(item, by=_user(request))
        return Response(self._detail(item))

    @staticmethod
    def _to_steer(request: Request, pk: str | None) -> WorkItem:
        """The work item, for an engineer or admin of its organisation (404 for an outsider)."""
        item = selectors.work_items_visible_to(request.user).filter(pk=_item_id(pk)).first()
        if item is None:
            raise NotFound(f"There is no work item {pk} in your organisations.")
        if not may_write_in(request.user, item.case.organisation_id):
            raise PermissionDenied(WRITERS_ONLY)
        return item

    @staticmethod
    def _detail(item: WorkItem) -> Any:
        # The service's copy, read under the case lock with its case and people attached:
        # reading it again would cost the request several ms after its commit, taken from
        # the worker that is moving the cobot.
        return WorkItemDetailSerializer(item).data


def _item_id(pk: str | None) -> int:
    """The work item an action names. Its services read it under its case's lock, through the
    user's memberships (404 for an outsider): a read here first would cost every action a query."""
    if pk is None or not ID_PATTERN.fullmatch(pk):
        raise NotFound(f"There is no work item {pk} in your organisations.")
    return int(pk)


def _kinds(request: Request) -> set[str]:
    raw = request.query_params.get("kind", WorkItemKind.OPERATOR)
    kinds = {kind.strip() for kind in raw.split(",") if kind.strip()}
    unknown = kinds - set(WorkItemKind.values)
    if unknown or not kinds:
        allowed = ", ".join(WorkItemKind.values)
        raise Rejected({"detail": f"kind must be one or more of {allowed}, comma-separated."})
    return kinds


# Incidents -----------------------------------------------------------------------------


@extend_schema_view(
    list=extend_schema(
        parameters=[
            OpenApiParameter(
                "all", bool, description="Resolved incidents too (default: open only)."
            ),
            OpenApiParameter("case", int, description="Only this case's incidents."),
        ]
    ),
    retrieve=extend_schema(responses={200: IncidentSerializer, **REFUSED_404}),
)
class IncidentViewSet(viewsets.ReadOnlyModelViewSet[Incident]):
    """What a person must decide about a case. Members read; engineers and admins resolve."""

    serializer_class = IncidentSerializer
    permission_classes = [WritersOfTheOrganisation]

    def get_queryset(self) -> QuerySet[Incident]:
        every = self.action != "list" or _flag(self.request, "all")
        incidents = selectors.incidents_visible_to(self.request.user, open_only=not every)
        case = _id_param(self.request, "case") if self.action == "list" else None
        return incidents if case is None else incidents.filter(case_id=case)

    @extend_schema(
        request=ResolveRequestSerializer, responses={200: IncidentSerializer, **WRITE_REFUSALS}
    )
    @action(detail=True, methods=["post"])
    def resolve(self, request: Request, pk: str | None = None) -> Response:
        """Retry the job, skip the task with the given outputs, or cancel the case."""
        body = ResolveRequestSerializer(data=request.data)
        body.is_valid(raise_exception=True)
        incident = services.resolve_incident(
            self.get_object(),
            by=_user(request),
            resolution=body.validated_data["resolution"],
            outputs=body.validated_data.get("outputs"),
            again=body.validated_data["again"],
        )
        fresh = selectors.incidents_visible_to(request.user, open_only=False).get(pk=incident.pk)
        return Response(IncidentSerializer(fresh).data)


# Cobot queues --------------------------------------------------------------------------


@extend_schema_view(
    list=extend_schema(
        parameters=[
            OpenApiParameter("cobot", int, description="Only this cobot's queue."),
            OpenApiParameter("device", int, description="Only this device's queue."),
        ]
    ),
    retrieve=extend_schema(responses={200: QueuedJobSerializer, **REFUSED_404}),
)
class JobViewSet(viewsets.ReadOnlyModelViewSet[Job]):
    """Cobot and device queues: queued and running jobs, per cobot and per device the running
    one first, then first come first served. A job by id in any state. Read-only."""

    serializer_class = QueuedJobSerializer

    def get_queryset(self) -> QuerySet[Job]:
        user = self.request.user
        if self.action != "list":
            return selectors.jobs_visible_to(user)
        cobot = _id_param(self.request, "cobot")
        device = _id_param(self.request, "device")
        queues = selectors.cobot_queues(user)
        if cobot is not None:
            queues = queues.filter(cobot_id=cobot)
        return queues if device is None else queues.filter(device_id=device)


# Messages ------------------------------------------------------------------------------


class MessageViewSet(viewsets.GenericViewSet[Any]):
    """Messages to cases, for machines and people with a writer's role."""

    permission_classes = [MembersReadWritersWrite]
    serializer_class = MessageRequestSerializer

    @extend_schema(
        request=MessageRequestSerializer,
        responses={
            201: MessageSerializer,
            200: MessageSerializer,
            400: RefusalSerializer,
            403: RefusalSerializer,
        },
    )
    def create(self, request: Request) -> Response:
        """Delivers a message to the case waiting for it, or keeps it until one does (its TTL).

        201 for a new message; 200 with the first message, unchanged, when its `message_id`
        was sent before.
        """
        body = MessageRequestSerializer(data=request.data, context={"request": request})
        body.is_valid(raise_exception=True)
        fields = dict(body.validated_data)
        organisation = target_organisation(request, fields.pop("organisation", None))
        message, created = receive_message(organisation, sent_by=_user(request), **fields)
        message.refresh_from_db()  # a case may have taken it meanwhile
        code = status.HTTP_201_CREATED if created else status.HTTP_200_OK
        return Response(MessageSerializer(message).data, status=code)


# Actor mappings ------------------------------------------------------------------------


class ActorMappingView(generics.GenericAPIView[PatternVersion]):
    """The default actor mapping of a published version (its cases may override it per actor)."""

    serializer_class = ActorMappingSerializer
    permission_classes = [WritersOfTheOrganisation]
    detail = True  # roles are checked on the version, once it is known to be visible

    def get_queryset(self) -> QuerySet[PatternVersion]:
        return versions_visible_to(self.request.user)

    @extend_schema(responses={200: ActorMappingSerializer, **REFUSED_404})
    def get(self, request: Request, pk: str) -> Response:
        return Response(ActorMappingSerializer(self.get_object()).data)

    @extend_schema(
        request=ActorMappingSerializer,
        responses={
            200: ActorMappingSerializer,
            400: RefusalSerializer,
            403: RefusalSerializer,
            404: RefusalSerializer,
        },
    )
    def put(self, request: Request, pk: str) -> Response:
        """Sets who performs each actor (engineers and admins); names are stored as ids."""
        version = self.get_object()
        body = ActorMappingSerializer(data=request.data)
        body.is_valid(raise_exception=True)
        mapping = body.validated_data["default_actor_mapping"]
        version = services.set_default_actor_mapping(version, mapping)
        return Response(ActorMappingSerializer(version).data)


# Query parameters ----------------------------------------------------------------------


def _id_param(request: Request, name: str) -> int | None:
    """An id in the query string; None when absent, a 400 when it is not an id."""
    return _whole_param(request, name, what="an id (a whole number)")


def _whole_param(request: Request, name: str, what: str = "a whole number") -> int | None:
    value = request.query_params.get(name)
    if value is None:
        return None
    if not ID_PATTERN.fullmatch(value):
        raise Rejected({"detail": f"{name} must be {what}."})
    return int(value)


def _flag(request: Request, name: str) -> bool:
    return request.query_params.get(name, "").lower() in {"1", "true", "yes"}


def _user(request: Request) -> Any:
    """The signed-in user; the permission classes have made sure there is one."""
    return request.user
