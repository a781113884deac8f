"""How cobots look over the API. Credentials appear only as their source, never as a secret."""

from typing import Any

from django.db.models import QuerySet
from rest_framework import serializers

from hrc.cobots.models import Cobot, CobotCommand, CredentialsSecret, Device
from hrc.cobots.selectors import cobots_visible_to
from hrc.organisations.api.serializers import MemberOrganisationField


class CobotSerializer(serializers.ModelSerializer[Cobot]):
    organisation = MemberOrganisationField(
        required=False,
        help_text="Where the cobot belongs; may be left out by a member of only one organisation.",
    )

    class Meta:
        model = Cobot
        fields = [
            "id",
            "organisation",
            "name",
            "driver",
            "endpoint",
            "credentials_source",
            "cell",
            "is_active",
            "stopped_at",
            "created_at",
            "updated_at",
        ]
        read_only_fields = ["id", "stopped_at", "created_at", "updated_at"]
        # The (organisation, name) constraint is checked by the service, after the
        # organisation is known; DRF's validator would need the organisation in the body.
        validators: list[object] = []

    def validate_organisation(self, organisation: object) -> object:
        if (
            self.instance is not None
            and getattr(organisation, "pk", None) != self.instance.organisation_id
        ):
            raise serializers.ValidationError("A cobot cannot move to another organisation.")
        return organisation


class ControlRequestSerializer(serializers.Serializer[dict[str, Any]]):
    confirm = serializers.BooleanField(
        default=False,
        help_text="Must be true: a person confirms every command to a cobot.",
    )


class LoadProgramRequestSerializer(ControlRequestSerializer):
    program = serializers.CharField(
        required=False,
        allow_blank=True,
        default="",
        max_length=300,
        help_text="The program's name as the cobot lists it (a directory and .urp are ignored).",
    )


class CobotCommandSerializer(serializers.ModelSerializer[CobotCommand]):
    """A control command as the record shows it."""

    requested_by: serializers.SlugRelatedField[Any] = serializers.SlugRelatedField(
        slug_field="username", read_only=True, allow_null=True
    )

    class Meta:
        model = CobotCommand
        fields = [
            "id",
            "cobot",
            "command",
            "arguments",
            "requested_by",
            "requested_at",
            "finished_at",
            "outcome",
            "message",
        ]
        read_only_fields = fields


class CommandRefusalSerializer(serializers.Serializer[dict[str, Any]]):
    """Why a command was not carried out; `command` is its record when it was recorded."""

    detail = serializers.CharField()
    code = serializers.CharField(
        required=False,
        help_text="The refusal's name for programs (invalid, not-allowed, conflict, ...); "
        "absent where the framework itself refused.",
    )
    command = CobotCommandSerializer(required=False)


class RegistersSerializer(serializers.Serializer[dict[str, Any]]):
    inputs = serializers.DictField(help_text="Input registers (what clients write) by name.")
    outputs = serializers.DictField(help_text="Output registers (what the program writes) by name.")


class CobotStateSerializer(serializers.Serializer[dict[str, Any]]):
    """What the cobot reports now (hrc.cobots.selectors.live_state)."""

    reachable = serializers.BooleanField()
    error = serializers.CharField(required=False, help_text="Why it cannot be reached.")
    transient = serializers.BooleanField(required=False, help_text="Whether trying again may help.")
    RobotMode = serializers.CharField(required=False)
    SafetyMode = serializers.CharField(required=False)
    ProgramState = serializers.CharField(required=False)
    CurrentProgram = serializers.CharField(required=False)
    LastError = serializers.CharField(required=False)


class CredentialsSecretSerializer(serializers.ModelSerializer[CredentialsSecret]):
    """A credentials secret as shown: its name and who set it, never the user name or password."""

    updated_by: serializers.SlugRelatedField[Any] = serializers.SlugRelatedField(
        slug_field="username", read_only=True, allow_null=True
    )

    class Meta:
        model = CredentialsSecret
        fields = ["id", "organisation", "name", "updated_by", "updated_at"]
        read_only_fields = fields


class SetCredentialsSecretSerializer(serializers.Serializer[dict[str, Any]]):
    """Creates a secret or replaces the one of that name; write-only."""

    organisation = serializers.IntegerField(
        required=False, help_text="Needed only when you are an admin of several organisations."
    )
    name = serializers.CharField(max_length=64, help_text="Cobots use it as 'secret:NAME'.")
    username = serializers.CharField(max_length=64, write_only=True)
    password = serializers.CharField(
        max_length=1024, write_only=True, trim_whitespace=False, style={"input_type": "password"}
    )


class VisibleCobotField(serializers.PrimaryKeyRelatedField[Cobot]):
    """A cobot id among the requesting user's organisations'; any other id is 'does not exist'."""

    def get_queryset(self) -> QuerySet[Cobot]:
        request = self.context.get("request")
        user = getattr(request, "user", None)
        return cobots_visible_to(user) if user is not None else Cobot.objects.none()


class DeviceSerializer(serializers.ModelSerializer[Device]):
    organisation = MemberOrganisationField(
        required=False,
        help_text="Where the device belongs; may be left out by an admin of only one organisation.",
    )
    gateway = VisibleCobotField(
        help_text="The id of the cobot whose OPC UA gateway serves the device (same organisation)."
    )

    class Meta:
        model = Device
        fields = ["id", "organisation", "name", "kind", "cell", "gateway", "is_active",
                  "created_at", "updated_at"]  # fmt: skip
        read_only_fields = ["id", "created_at", "updated_at"]
        validators: list[object] = []  # the service checks the name, once the organisation is known

    def validate_organisation(self, organisation: object) -> object:
        if (
            self.instance is not None
            and getattr(organisation, "pk", None) != self.instance.organisation_id
        ):
            raise serializers.ValidationError("A device cannot move to another organisation.")
        return organisation
