"""How running cases look over the API: cases, work items, jobs, incidents, events, messages.

Users appear as their usernames. Request bodies have their own serializers
(…RequestSerializer): the views hand their validated data to the services.
"""

from typing import Any

from django.db.models import QuerySet, TextChoices
from drf_spectacular.extensions import OpenApiSerializerFieldExtension
from drf_spectacular.openapi import AutoSchema
from drf_spectacular.plumbing import build_choice_field
from drf_spectacular.types import OpenApiTypes
from drf_spectacular.utils import Direction, extend_schema_field
from rest_framework import serializers

from hrc.cases.choices import (
    CaseStatus,
    EventType,
    IncidentKind,
    InterruptionMode,
    JobState,
    Resolution,
    WorkItemKind,
    WorkItemState,
)
from hrc.cases.messages import DEFAULT_TTL_SECONDS, MAX_TTL_SECONDS
from hrc.cases.models import Case, CaseEvent, Incident, Interruption, Job, Message, WorkItem
from hrc.cases.nets import net_of
from hrc.organisations.api.serializers import MemberOrganisationField
from hrc.patterns.models import PatternVersion
from hrc.patterns.selectors import versions_visible_to


def _username() -> Any:
    return serializers.SlugRelatedField(slug_field="username", read_only=True)


class RefusalSerializer(serializers.Serializer[dict[str, Any]]):
    """Why a request was refused: 400 wrong input, 403 not yours, 404 not found, 409 moved on."""

    detail = serializers.CharField()
    code = serializers.CharField(
        required=False,
        help_text="The refusal's name for programs (invalid, not-allowed, conflict, ...); "
        "absent where the framework itself refused.",
    )


class EnumField(serializers.ChoiceField):
    """A read-only choice field documented as the enum component named after its TextChoices.

    Work items and jobs both have a `kind` and a `state` with different choices;
    drf-spectacular names enums after the field and would warn (and hash the names).
    """

    def __init__(self, choices: type[TextChoices], **kwargs: Any) -> None:
        self.enum_name = f"{choices.__name__}Enum"
        super().__init__(choices=choices.choices, read_only=True, **kwargs)


# drf-spectacular's extension base registers subclasses in an unannotated __init_subclass__.
class _EnumFieldSchema(OpenApiSerializerFieldExtension):  # type: ignore[no-untyped-call]
    target_class = EnumField

    def get_name(self) -> str:
        return str(self.target.enum_name)

    def map_serializer_field(self, auto_schema: AutoSchema, direction: Direction) -> Any:
        schema = build_choice_field(self.target)
        schema.pop("x-spec-enum-id", None)  # a component of its own, not one for the enum hook
        return schema


# Jobs and work items ---------------------------------------------------------------------


class JobSerializer(serializers.ModelSerializer[Job]):
    """A command to a cobot or a device: where it stands in its queue and what it waits for."""

    cobot_name = serializers.CharField(
        source="cobot.name", read_only=True, allow_null=True, help_text="null for a device's job."
    )
    device_name = serializers.CharField(
        source="device.name", read_only=True, allow_null=True,
        help_text="The device whose queue a device call waits in; null for a cobot's job.",
    )  # fmt: skip
    kind = EnumField(WorkItemKind)
    state = EnumField(JobState)
    queue_position = serializers.IntegerField(
        read_only=True,
        allow_null=True,
        help_text="0: on its cobot or device now; 1: next in line; …; null: no longer queued.",
    )

    class Meta:
        model = Job
        fields = [
            "id",
            "cobot",
            "cobot_name",
            "device",
            "device_name",
            "kind",
            "state",
            "queue_position",
            "waiting_for",
            "attempt",
            "retries_left",
            "last_error",
            "command",
            "queued_at",
            "next_try_at",
            "started_at",
            "ended_at",
        ]
        read_only_fields = fields


class QueuedJobSerializer(JobSerializer):
    """A job in a cobot's queue, with the case and task it is for."""

    task = serializers.CharField(source="work_item.task", read_only=True)

    class Meta(JobSerializer.Meta):
        fields = [*JobSerializer.Meta.fields, "case", "work_item", "task"]
        read_only_fields = fields

    def get_fields(self) -> dict[str, serializers.Field[Any, Any, Any, Any]]:
        # Added here: a class attribute named `label` would shadow Field.label.
        fields = super().get_fields()
        fields["label"] = serializers.CharField(source="work_item.label", read_only=True)
        return fields


class WorkItemSerializer(serializers.ModelSerializer[WorkItem]):
    """One task of a case offered to operators or queued for a cobot (then with its job)."""

    case_status = serializers.CharField(
        source="case.status", read_only=True, help_text="Nothing starts while it is suspended."
    )
    kind = EnumField(WorkItemKind)
    state = EnumField(WorkItemState)
    claimed_by = _username()
    job = serializers.SerializerMethodField(help_text="Cobot and device tasks only.")

    class Meta:
        model = WorkItem
        fields = [
            "id",
            "case",
            "case_status",
            "task",
            "label",
            "actor",
            "kind",
            "state",
            "team",
            "cobot",
            "claimed_by",
            "offered_at",
            "started_at",
            "ended_at",
            "job",
        ]
        read_only_fields = fields

    @extend_schema_field(JobSerializer(allow_null=True))
    def get_job(self, item: WorkItem) -> dict[str, Any] | None:
        if item.kind == WorkItemKind.OPERATOR:
            return None  # an operator's task never has one: no query to find out
        job = getattr(item, "job", None)
        if job is None:
            return None
        # The position is annotated on the work item (selectors.work_items_visible_to), and
        # the job's cobot or device is the item's, read along: no query per row for its name.
        job.queue_position = getattr(item, "queue_position", None)
        if job.cobot_id == item.cobot_id and WorkItem.cobot.is_cached(item):
            job.cobot = item.cobot
        if job.device_id == item.device_id and WorkItem.device.is_cached(item):
            job.device = item.device
        return JobSerializer(job).data


class WorkItemDetailSerializer(WorkItemSerializer):
    """A work item with what the performer needs: the instructions and the form to fill in."""

    form = serializers.SerializerMethodField(
        help_text="The JSON Schema the completion's data must satisfy; null when there is none."
    )
    completed_by = _username()

    class Meta(WorkItemSerializer.Meta):
        fields = [*WorkItemSerializer.Meta.fields, "instructions", "form", "result", "completed_by"]
        read_only_fields = fields

    @extend_schema_field(OpenApiTypes.OBJECT)
    def get_form(self, item: WorkItem) -> dict[str, Any] | None:
        config = net_of(item.case).tasks.get(item.task)
        return dict(config.form) if config is not None and config.form is not None else None


class PerformerSerializer(serializers.Serializer[Any]):
    id = serializers.IntegerField(read_only=True)
    username = serializers.CharField(read_only=True)


class ReassignRequestSerializer(serializers.Serializer[dict[str, Any]]):
    user = serializers.IntegerField(
        allow_null=True,
        help_text="Who does the task now: a member who may (a candidate, or in its team). "
        "null gives a claimed task back to its candidates.",
    )


class CompleteRequestSerializer(serializers.Serializer[dict[str, Any]]):
    def get_fields(self) -> dict[str, serializers.Field[Any, Any, Any, Any]]:
        # Declared here: a class attribute named `data` would shadow Serializer.data.
        return {
            "data": serializers.DictField(
                required=False, help_text="The filled-in form; checked against the task's form."
            )
        }


# Incidents -------------------------------------------------------------------------------


class IncidentSerializer(serializers.ModelSerializer[Incident]):
    task = serializers.CharField(source="work_item.task", read_only=True, allow_null=True)
    kind = EnumField(IncidentKind)
    resolved_by = _username()

    class Meta:
        model = Incident
        fields = [
            "id",
            "case",
            "work_item",
            "task",
            "kind",
            "message",
            "cobot_state",
            "opened_at",
            "resolved_at",
            "resolution",
            "resolved_by",
        ]
        read_only_fields = fields


class ResolveRequestSerializer(serializers.Serializer[dict[str, Any]]):
    resolution = serializers.ChoiceField(
        choices=Resolution.choices,
        help_text="retry: queue the job again; skip: the task completes with `outputs`; "
        "cancel: cancel the case.",
    )
    outputs = serializers.DictField(
        required=False, help_text="skip: the task's result, mapped into the case data."
    )
    again = serializers.BooleanField(
        default=False,
        help_text="retry: run a step the cobot may have run already once more (a new attempt).",
    )


# Cases -----------------------------------------------------------------------------------


class CaseSummarySerializer(serializers.ModelSerializer[Case]):
    """A case without its data, for lists."""

    pattern = serializers.IntegerField(source="version.pattern_id", read_only=True)
    pattern_name = serializers.CharField(source="version.pattern.name", read_only=True)
    version_number = serializers.IntegerField(source="version.number", read_only=True)
    status = EnumField(CaseStatus)
    started_by = _username()

    class Meta:
        model = Case
        fields = [
            "id",
            "organisation",
            "pattern",
            "pattern_name",
            "version",
            "version_number",
            "status",
            "reference",
            "started_by",
            "started_at",
            "ended_at",
        ]
        read_only_fields = fields


class CaseSerializer(CaseSummarySerializer):
    """A case with its marking, data, open work items and open incidents."""

    marking = serializers.DictField(
        child=serializers.IntegerField(), read_only=True, help_text="Tokens per place."
    )
    actor_mapping = serializers.DictField(child=serializers.DictField(), read_only=True)
    work_items = WorkItemSerializer(
        source="open_work_items", many=True, read_only=True, help_text="Open work items."
    )
    incidents = IncidentSerializer(
        source="open_incidents", many=True, read_only=True, help_text="Unresolved incidents."
    )

    class Meta(CaseSummarySerializer.Meta):
        fields = [
            *CaseSummarySerializer.Meta.fields,
            "marking",
            "data",
            "actor_mapping",
            "last_seq",
            "work_items",
            "incidents",
        ]
        read_only_fields = fields

    def get_fields(self) -> dict[str, serializers.Field[Any, Any, Any, Any]]:
        fields = super().get_fields()
        # Replaced here: a class attribute named `data` would shadow Serializer.data.
        fields["data"] = serializers.DictField(read_only=True, help_text="The case data.")
        return fields


@extend_schema_field(OpenApiTypes.INT)
class VisibleVersionField(serializers.PrimaryKeyRelatedField[PatternVersion]):
    """A published version of one of the requesting user's organisations; any other is unknown."""

    def get_queryset(self) -> QuerySet[PatternVersion]:
        request = self.context.get("request")
        user = getattr(request, "user", None)
        if user is None:
            return PatternVersion.objects.none()
        return versions_visible_to(user)


class StartCaseRequestSerializer(serializers.Serializer[dict[str, Any]]):
    version = VisibleVersionField(help_text="The published pattern version to run.")
    actor_mapping = serializers.DictField(
        child=serializers.DictField(),
        required=False,
        help_text="Overrides the version's default mapping per actor: {actor: {users: [...]} | "
        "{team: id or name} | {cobot: id or name} | {device: id or name}}. Not for operators: they start with the defaults.",
    )
    reference = serializers.CharField(
        required=False,
        allow_blank=True,
        max_length=100,
        default="",
        help_text="What the case works on: an order or workpiece number.",
    )
    cell = serializers.CharField(
        required=False,
        allow_blank=True,
        default="",
        max_length=50,
        help_text="The cell whose tablet starts it: operators start only at one of the version's start cells.",
    )

    def get_fields(self) -> dict[str, serializers.Field[Any, Any, Any, Any]]:
        fields = super().get_fields()
        # Added here: a class attribute named `data` would shadow Serializer.data.
        fields["data"] = serializers.DictField(
            required=False, help_text="The case data to start with."
        )
        return fields


class CancelRequestSerializer(serializers.Serializer[dict[str, Any]]):
    reason = serializers.CharField(required=False, allow_blank=True, max_length=1000)


class CaseEventSerializer(serializers.ModelSerializer[CaseEvent]):
    type = EnumField(EventType)
    user = _username()

    class Meta:
        model = CaseEvent
        fields = [
            "seq",
            "at",
            "type",
            "task",
            "actor",
            "work_item",
            "user",
            "marking_before",
            "marking_after",
            "detail",
        ]
        read_only_fields = fields


class InterruptionSerializer(serializers.ModelSerializer[Interruption]):
    """A task held while another worked in the area they share (a space constraint): a cobot's
    step paused or slowed, or a task kept out (a cobot's step waiting, an operator refused)."""

    task = serializers.CharField(source="work_item.task", read_only=True)
    actor = serializers.CharField(
        source="work_item.actor", read_only=True, help_text="The held task's pattern actor."
    )
    by_work_item = serializers.IntegerField(
        source="by_work_item_id", read_only=True, help_text="The task in the area."
    )
    by_task = serializers.CharField(source="by_work_item.task", read_only=True)
    by_actor = serializers.CharField(
        source="by_work_item.actor", read_only=True, help_text="The pattern actor in the area."
    )
    cobot_name = serializers.CharField(source="cobot.name", read_only=True, allow_null=True)
    mode = EnumField(InterruptionMode)
    seconds = serializers.FloatField(
        read_only=True, allow_null=True,
        help_text="How long the other task was in the area; null while it still is.",
    )  # fmt: skip
    settled = serializers.BooleanField(
        read_only=True, help_text="Over, and the cobot no longer paused or slowed by it."
    )

    class Meta:
        model = Interruption
        fields = [
            "id",
            "work_item",
            "task",
            "actor",
            "by_work_item",
            "by_task",
            "by_actor",
            "cobot",
            "cobot_name",
            "mode",
            "started_at",
            "ended_at",
            "seconds",
            "paused_at",
            "resumed_at",
            "settled",
            "error",
        ]
        read_only_fields = fields


class ActorMappingSerializer(serializers.Serializer[PatternVersion]):
    """Who performs each actor of a version's cases unless a case says otherwise."""

    version = serializers.IntegerField(source="pk", read_only=True)
    actor_mapping = serializers.DictField(
        child=serializers.DictField(),
        source="default_actor_mapping",
        help_text="{actor: {users: [ids or usernames]} | {team: id or name} | "
        "{cobot: id or name} | {device: id or name}}; stored with ids.",
    )


# Messages --------------------------------------------------------------------------------


class MessageSerializer(serializers.ModelSerializer[Message]):
    """A message as it was received; `case` and `consumed_at` are set once a case took it."""

    class Meta:
        model = Message
        fields = [
            "id",
            "organisation",
            "message_id",
            "name",
            "correlation",
            "payload",
            "received_at",
            "expires_at",
            "case",
            "transition",
            "consumed_at",
        ]
        read_only_fields = fields


@extend_schema_field(OpenApiTypes.INT)
class _OrganisationId(MemberOrganisationField):
    """An organisation id in a body without a model (the schema cannot infer the type)."""


class MessageRequestSerializer(serializers.Serializer[dict[str, Any]]):
    message_id = serializers.CharField(
        max_length=200, help_text="Your id for the message: sending it again changes nothing."
    )
    name = serializers.CharField(max_length=200)
    correlation = serializers.DictField(
        required=False, help_text="Keys a waiting case's correlation expressions must equal."
    )
    payload = serializers.DictField(required=False, help_text="Merged into the case's data.")
    ttl_seconds = serializers.IntegerField(
        min_value=1,
        max_value=MAX_TTL_SECONDS,
        default=DEFAULT_TTL_SECONDS,
        help_text="How long the message waits for a case that is not waiting yet.",
    )
    organisation = _OrganisationId(
        required=False,
        help_text="Where the message goes; may be left out by a member of only one organisation.",
    )
