"""How patterns and their versions look over the API."""

from typing import Any

from drf_spectacular.utils import extend_schema_field
from rest_framework import serializers

from hrc.engine.durations import Duration, DurationError, duration_from_dict
from hrc.engine.startdata import defaults_of, start_schema
from hrc.organisations.api.serializers import MemberOrganisationField
from hrc.organisations.models import Organisation
from hrc.patterns.models import PatternModel, PatternVersion
from hrc.patterns.prediction import MAX_CASES, MAX_PARALLEL, Options


class PatternSummarySerializer(serializers.ModelSerializer[PatternModel]):
    """A pattern without its draft, for lists."""

    created_by: serializers.SlugRelatedField[Any] = serializers.SlugRelatedField(
        slug_field="username", read_only=True
    )
    latest_version = serializers.SerializerMethodField(
        help_text="The number of the newest published version; null if never published."
    )

    class Meta:
        model = PatternModel
        fields = [
            "id",
            "organisation",
            "name",
            "description",
            "latest_version",
            "created_by",
            "created_at",
            "updated_at",
            "archived_at",
        ]
        read_only_fields = fields

    def get_latest_version(self, pattern: PatternModel) -> int | None:
        number = getattr(pattern, "latest_version", None)
        return int(number) if number is not None else None


class PatternSerializer(PatternSummarySerializer):
    """A pattern with its draft. The organisation is set at creation and fixed afterwards."""

    organisation = MemberOrganisationField(
        required=False,
        help_text="Where the pattern goes; may be left out by a member of only one organisation.",
    )
    draft = serializers.JSONField(
        required=False,
        help_text=(
            "An hrc-pattern/1 document; it must have the right shape but may break the "
            "model's rules (POST /check/ reports them). Left out on creation: an empty net."
        ),
    )

    class Meta(PatternSummarySerializer.Meta):
        fields = [*PatternSummarySerializer.Meta.fields, "draft"]
        read_only_fields = [
            "id",
            "latest_version",
            "created_by",
            "created_at",
            "updated_at",
            "archived_at",
        ]

    def validate_organisation(self, organisation: Organisation) -> Organisation:
        if self.instance is not None and organisation.pk != self.instance.organisation_id:
            raise serializers.ValidationError("A pattern cannot move to another organisation.")
        return organisation


class PatternVersionSummarySerializer(serializers.ModelSerializer[PatternVersion]):
    published_by: serializers.SlugRelatedField[Any] = serializers.SlugRelatedField(
        slug_field="username", read_only=True
    )
    pattern_name = serializers.CharField(source="pattern.name", read_only=True)
    pattern_class = serializers.SerializerMethodField(
        help_text="The collaboration pattern(s) the check found: synchronized, cooperation, …"
    )
    start_form = serializers.SerializerMethodField(
        help_text="The start data as a JSON Schema: one field per key of the pattern's data."
    )

    class Meta:
        model = PatternVersion
        fields = [
            "id",
            "pattern",
            "pattern_name",
            "pattern_class",
            "number",
            "published_by",
            "published_at",
            "retired_at",
            "start_roles",
            "start_cells",
            "start_form",
        ]
        read_only_fields = fields

    def get_pattern_class(self, version: PatternVersion) -> list[str]:
        return list(version.report.get("patterns", []))

    def get_start_form(self, version: PatternVersion) -> dict[str, Any]:
        return start_schema(defaults_of(version.document))


class StartRightsSerializer(serializers.Serializer[dict[str, Any]]):
    roles = serializers.ListField(
        child=serializers.CharField(),
        help_text="Roles that may start cases: admin, engineer, operator.",
    )
    cells = serializers.ListField(
        child=serializers.CharField(),
        required=False,
        default=list,
        help_text="Cells whose tablets offer operators to start a case.",
    )


class SwitchSerializer(serializers.Serializer[dict[str, Any]]):
    on = serializers.BooleanField(help_text="true: retire (or archive); false: back in service.")


class PatternVersionSerializer(PatternVersionSummarySerializer):
    """A published version with the document and the check report it was published with."""

    document = serializers.JSONField(read_only=True)
    report = serializers.JSONField(read_only=True)

    class Meta(PatternVersionSummarySerializer.Meta):
        fields = [*PatternVersionSummarySerializer.Meta.fields, "document", "report"]
        read_only_fields = fields


# The serializers below document the engine's answers in the OpenAPI schema; the views
# pass the engine's data through as it is.


class CheckIssueSerializer(serializers.Serializer[dict[str, Any]]):
    code = serializers.CharField(
        help_text="A stable code from pattern-format.md, e.g. duplicate-id."
    )
    message = serializers.CharField()
    elements = serializers.ListField(child=serializers.CharField())
    witness = serializers.ListField(
        child=serializers.CharField(),
        required=False,
        help_text="For behavioural issues: a firing sequence that shows the problem.",
    )


class _WithIssueLists(serializers.Serializer[dict[str, Any]]):
    """Adds issue lists named in `issue_lists`.

    They are added in get_fields because a class attribute named `errors` would
    collide with Serializer.errors.
    """

    issue_lists: tuple[str, ...] = ()

    def get_fields(self) -> dict[str, serializers.Field[Any, Any, Any, Any]]:
        fields = super().get_fields()
        for name in self.issue_lists:
            fields[name] = CheckIssueSerializer(many=True)
        return fields


class CheckReportSerializer(_WithIssueLists):
    issue_lists = ("errors", "warnings")

    valid = serializers.BooleanField(help_text="No error: publishable when sound is not false.")
    patterns = serializers.ListField(
        child=serializers.CharField(), help_text="Every pattern whose requirements hold."
    )
    sound = serializers.BooleanField(
        allow_null=True, help_text="null when a rule was broken before soundness could be decided."
    )
    stats = serializers.DictField(child=serializers.IntegerField(), required=False)


class PublishRefusedSerializer(serializers.Serializer[dict[str, Any]]):
    detail = serializers.CharField()
    code = serializers.CharField(
        required=False,
        help_text="The refusal's name for programs (invalid, not-allowed, conflict, ...); "
        "absent where the framework itself refused.",
    )
    report = CheckReportSerializer()


class DocumentErrorSerializer(_WithIssueLists):
    issue_lists = ("errors",)

    detail = serializers.CharField()


class _Labelled(serializers.Serializer[dict[str, Any]]):
    """Adds `label` in get_fields: a class attribute of that name would shadow Field.label."""

    label_help = ""

    def get_fields(self) -> dict[str, serializers.Field[Any, Any, Any, Any]]:
        fields = super().get_fields()
        fields = {
            "id": fields.pop("id"),
            "label": serializers.CharField(help_text=self.label_help),
        } | fields
        return fields


class NetPlaceSerializer(_Labelled):
    label_help = "How the editor can name it."

    id = serializers.CharField(help_text="p2, running:tc1, time:to1>tc2, func-start:tc2>to1, ...")
    tokens = serializers.IntegerField(help_text="In the initial marking.")
    kind = serializers.ChoiceField(
        ["flow", "busy", "constraint"],
        help_text="flow: a place of the pattern; busy: marked while a task runs; constraint: added by a constraint.",
    )
    of = serializers.JSONField(
        help_text=(
            "The pattern's elements it stands for: flow, the place's id; busy, the task's id; "
            "constraint, [from, to] as the constraint is written."
        )
    )
    constraint = serializers.JSONField(
        required=False,
        help_text=(
            "Constraint places: {index: in the document's constraints, type, "
            "role: time | func-start | func-done}."
        ),
    )
    needs = serializers.CharField(
        required=False, help_text="Constraint places: what the task that takes the token waits for."
    )


class NetTransitionSerializer(_Labelled):
    label_help = "As a firing sequence (a witness) names it: start tc1, t1."

    id = serializers.CharField(help_text="start:tc1, complete:tc1, or a silent transition's id.")
    kind = serializers.ChoiceField(["start", "complete", "silent"])
    task = serializers.CharField(help_text="The pattern transition it belongs to.")
    performer = serializers.CharField(allow_null=True)


class ExecutionNetSerializer(serializers.Serializer[dict[str, Any]]):
    """The execution net of a pattern (hrc/engine/tokengame.py) for the token game."""

    places = NetPlaceSerializer(many=True)
    transitions = NetTransitionSerializer(many=True)
    arcs = serializers.ListField(
        child=serializers.ListField(child=serializers.CharField(), min_length=2, max_length=2),
        help_text="[from, to]; each moves one token.",
    )
    initial = serializers.DictField(child=serializers.IntegerField(), help_text="Place -> tokens.")
    final = serializers.DictField(
        child=serializers.IntegerField(), help_text="The marking of a properly ended case."
    )
    ignored = serializers.ListField(
        child=serializers.CharField(),
        help_text="Constraint places, which proper completion does not look at.",
    )


@extend_schema_field(
    {
        "type": "object",
        "properties": {
            "kind": {"type": "string", "enum": ["fixed", "triangular", "lognormal", "empirical"]}
        },
        "required": ["kind"],
        "description": "fixed: seconds; triangular: low, mode, high; lognormal: mu and "
        "sigma, median and p90, or mean and sd; empirical: samples (seconds).",
    }
)
class DurationField(serializers.Field):  # type: ignore[type-arg]
    """A task's time: `{"kind": "fixed", "seconds": 3}`, triangular (low, mode, high) or
    lognormal (mu and sigma, median and p90, or mean and sd); read by the engine."""

    def to_internal_value(self, data: Any) -> Duration:
        if not isinstance(data, dict):
            raise serializers.ValidationError("A time is an object with a 'kind'.")
        try:
            return duration_from_dict(data)
        except DurationError as exc:
            raise serializers.ValidationError(str(exc)) from None

    def to_representation(self, value: Duration) -> dict[str, Any]:
        return value.as_dict()


class PredictOptionsSerializer(serializers.Serializer[Any]):
    cases = serializers.IntegerField(min_value=1, max_value=MAX_CASES, default=1000)
    parallel = serializers.IntegerField(min_value=1, max_value=MAX_PARALLEL, default=1)
    seed = serializers.IntegerField(min_value=0, max_value=2**63 - 1, default=0)
    people = serializers.DictField(
        child=serializers.IntegerField(min_value=1, max_value=MAX_PARALLEL),
        default=dict,
        help_text="Operator actor → persons in its team (1 when not given).",
    )
    durations = serializers.DictField(
        child=DurationField(), default=dict, help_text="Task id → its time."
    )
    weights = serializers.DictField(
        child=serializers.FloatField(min_value=0, max_value=1e9),
        default=dict,
        help_text="Transition id → its weight among the branches of its choice.",
    )
    measured = serializers.BooleanField(
        default=True, help_text="Use measured times where no time is given."
    )

    def options(self) -> Options:
        return Options(**self.validated_data)


class PredictRequestSerializer(serializers.Serializer[Any]):
    document = serializers.JSONField(help_text="The hrc-pattern/1 document to predict.")
    pattern = serializers.IntegerField(
        required=False,
        min_value=1,
        help_text="The pattern the draft belongs to: its earlier versions' cases give measured times.",
    )
    compare_version = serializers.IntegerField(
        required=False, min_value=1, help_text="A published version predicted the same way."
    )
    options = PredictOptionsSerializer(required=False)


class PredictionSerializer(serializers.Serializer[Any]):
    """The answer of POST /patterns/predict/ (hrc.engine.prediction_report.Prediction's fields)."""

    prediction = serializers.JSONField()
    durations = serializers.JSONField(help_text="Task id → where its time came from.")
    compared = serializers.JSONField(allow_null=True)
