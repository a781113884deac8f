"""Cobots of your organisations: members read, engineers and admins write and control them.

Control (hrc.cobots.control): engineers and admins of the cobot's
organisation power it, release its brakes and run its programs, each with
`"confirm": true`, each recorded; operators read the state, the registers
and the record (403 on commands); another organisation's cobot is 404.
Nothing clears a protective or emergency stop, and registers are not
written here (a register write can move the robot: the step handshake's job).

The prototype's client service (shared/reference/prototype-artefacts.md §2.2) maps so:

| prototype client service               | hrc                                                     |
| -------------------------------------- | ------------------------------------------------------- |
| `GET /cobots`                          | `GET /api/cobots/`                                      |
| `POST /cobots/:id/power_on`            | `POST /api/cobots/{id}/power-on/` (then Running)        |
| (PowerOn's brake release once Idle)    | `POST /api/cobots/{id}/brake-release/`                  |
| `POST /cobots/:id/power_off`           | `POST /api/cobots/{id}/power-off/`                      |
| `GET /cobots/:id/programs`             | `GET /api/cobots/{id}/programs/`                        |
| `POST /cobots/:id/programs/*/select`   | `POST /api/cobots/{id}/program/` `{"program": name}`    |
| `POST /cobots/:id/programs/start`      | `POST /api/cobots/{id}/program/start/`                  |
| `POST /cobots/:id/programs/pause`      | `POST /api/cobots/{id}/program/pause/`                  |
| `POST /cobots/:id/programs/stop`       | `POST /api/cobots/{id}/program/stop/`                   |
| `GET /cobots/:id/node/*` (registers)   | `GET /api/cobots/{id}/registers/?names=Int24,Bit64`     |
| `GET /cobots/:id/node/State/*`         | `GET /api/cobots/{id}/state/`                           |
| `PUT /cobots/:id/node/*`, `/position/` | not offered: steps go through cases (`/api/jobs/`)      |
| `POST /cobots/:id/handshake/:bit`      | not offered: the worker runs the handshake of each step |
| (none: who did what, when)             | `GET /api/cobots/{id}/commands/`                        |

Every command body also carries `"confirm": true`.
"""

from collections.abc import Callable
from typing import Any, TypeVar

from django.db.models import QuerySet
from drf_spectacular.types import OpenApiTypes
from drf_spectacular.utils import OpenApiParameter, extend_schema
from rest_framework import mixins, serializers, status, viewsets
from rest_framework.decorators import action
from rest_framework.exceptions import PermissionDenied
from rest_framework.request import Request
from rest_framework.response import Response

from hrc.api.permissions import MembersReadWritersWrite, target_organisation
from hrc.cobots import control, services
from hrc.cobots.api.serializers import (
    CobotCommandSerializer,
    CobotSerializer,
    CobotStateSerializer,
    CommandRefusalSerializer,
    ControlRequestSerializer,
    CredentialsSecretSerializer,
    DeviceSerializer,
    LoadProgramRequestSerializer,
    RegistersSerializer,
    SetCredentialsSecretSerializer,
)
from hrc.cobots.choices import ControlCommand
from hrc.cobots.models import Cobot, CobotCommand, CredentialsSecret, Device
from hrc.cobots.selectors import cobots_visible_to, commands_of, devices_visible_to, live_state
from hrc.organisations.choices import Role
from hrc.organisations.models import Organisation
from hrc.organisations.selectors import is_admin_of, memberships_of, organisations_of

COMMAND_RESPONSES: dict[int | str, Any] = {
    200: CobotCommandSerializer,
    **dict.fromkeys((400, 403, 404, 409, 502, 503, 504), CommandRefusalSerializer),
}
Action = TypeVar("Action", bound=Callable[..., Response])

READ_RESPONSES: dict[int | str, Any] = dict.fromkeys((400, 404, 502, 503), CommandRefusalSerializer)


def _command_schema(
    summary: str,
    request: type[serializers.Serializer[Any]] = ControlRequestSerializer,
) -> Callable[[Action], Action]:
    decorate: Callable[[Action], Action] = extend_schema(
        summary=summary,
        description=(
            "Engineers and admins of the cobot's organisation, with `confirm: true` (400 "
            "without). Recorded with who and when (`commands/`). 409 while a case's step runs "
            "on the cobot, while another command on it runs, or when the cobot refuses (a "
            "protective stop: in the gateway's words; nothing here clears one); 503 when the "
            "cobot cannot be reached, 504 when it did not answer in time."
        ),
        request=request,
        responses=COMMAND_RESPONSES,
    )
    return decorate


class CobotViewSet(viewsets.ModelViewSet[Cobot]):
    """The cobots of your organisations; another organisation's cobot is 404."""

    serializer_class = CobotSerializer
    permission_classes = [MembersReadWritersWrite]

    def get_queryset(self) -> QuerySet[Cobot]:
        return cobots_visible_to(self.request.user).order_by("name", "id")

    def perform_create(self, serializer: serializers.BaseSerializer[Cobot]) -> None:
        fields = dict(serializer.validated_data)
        organisation = target_organisation(self.request, fields.pop("organisation", None))
        serializer.instance = services.create_cobot(organisation, **fields)

    def perform_update(self, serializer: serializers.BaseSerializer[Cobot]) -> None:
        assert serializer.instance is not None
        changes = dict(serializer.validated_data)
        changes.pop("organisation", None)  # validated to be unchanged
        services.update_cobot(serializer.instance, **changes)

    def perform_destroy(self, instance: Cobot) -> None:
        services.delete_cobot(instance)

    # Control ---------------------------------------------------------------------------

    @_command_schema("Power on and release the brakes (URUA's PowerOn)")
    @action(detail=True, methods=["post"], url_path="power-on")
    def power_on(self, request: Request, pk: str | None = None) -> Response:
        return self._run(request, ControlCommand.POWER_ON)

    @_command_schema("Release the brakes of a cobot powered on to Idle")
    @action(detail=True, methods=["post"], url_path="brake-release")
    def brake_release(self, request: Request, pk: str | None = None) -> Response:
        return self._run(request, ControlCommand.BRAKE_RELEASE)

    @_command_schema("Power off (stops the program first)")
    @action(detail=True, methods=["post"], url_path="power-off")
    def power_off(self, request: Request, pk: str | None = None) -> Response:
        return self._run(request, ControlCommand.POWER_OFF)

    @_command_schema(
        "Load (select) a program; a playing one must be stopped first", LoadProgramRequestSerializer
    )
    @action(detail=True, methods=["post"], url_path="program")
    def load_program(self, request: Request, pk: str | None = None) -> Response:
        return self._run(request, ControlCommand.LOAD_PROGRAM, LoadProgramRequestSerializer)

    @_command_schema("Start (or resume) the loaded program")
    @action(detail=True, methods=["post"], url_path="program/start")
    def start_program(self, request: Request, pk: str | None = None) -> Response:
        return self._run(request, ControlCommand.START_PROGRAM)

    @_command_schema("Pause the playing program")
    @action(detail=True, methods=["post"], url_path="program/pause")
    def pause_program(self, request: Request, pk: str | None = None) -> Response:
        return self._run(request, ControlCommand.PAUSE_PROGRAM)

    @_command_schema("Stop the program")
    @action(detail=True, methods=["post"], url_path="program/stop")
    def stop_program(self, request: Request, pk: str | None = None) -> Response:
        return self._run(request, ControlCommand.STOP_PROGRAM)

    def _run(
        self,
        request: Request,
        command: ControlCommand,
        body_serializer: type[ControlRequestSerializer] = ControlRequestSerializer,
    ) -> Response:
        cobot = self.get_object()  # the wall (404) and the role (403) before anything else
        body = body_serializer(data=request.data)
        body.is_valid(raise_exception=True)
        try:
            record = control.run_command(
                cobot,
                command,
                by=request.user,  # type: ignore[arg-type]  # authenticated: the permission
                confirmed=body.validated_data["confirm"],
                program=body.validated_data.get("program", ""),
            )
        except control.ControlError as error:
            # Not an answer made here (the API's handler makes it): only the record, which
            # only this layer can serialise, joins the refusal's body.
            if error.record is not None:
                error.extra["command"] = CobotCommandSerializer(error.record).data
            raise
        return Response(CobotCommandSerializer(record).data)

    # Reads -----------------------------------------------------------------------------

    @extend_schema(
        summary="The cobot's state now",
        description="Robot mode, safety mode, program state and program, last error; "
        "`reachable: false` with the reason when the cobot cannot be reached.",
        responses={200: CobotStateSerializer, 404: CommandRefusalSerializer},
    )
    @action(detail=True, methods=["get"])
    def state(self, request: Request, pk: str | None = None) -> Response:
        return Response(live_state(self.get_object()))

    @extend_schema(
        summary="The cobot's input and output registers",
        description="All of them, or those `names` lists; a name that is no register is 400.",
        parameters=[
            OpenApiParameter(
                "names", OpenApiTypes.STR, description="Comma-separated, e.g. Int24,Bit64."
            )
        ],
        responses={200: RegistersSerializer, **READ_RESPONSES},
    )
    @action(detail=True, methods=["get"])
    def registers(self, request: Request, pk: str | None = None) -> Response:
        cobot = self.get_object()
        names = control.register_names(request.query_params.get("names"))
        registers = control.read_registers(cobot, names)
        return Response({"inputs": registers.inputs, "outputs": registers.outputs})

    @extend_schema(
        summary="The programs the cobot can load",
        responses={
            200: serializers.ListSerializer(child=serializers.CharField()),
            **READ_RESPONSES,
        },
    )
    @action(detail=True, methods=["get"])
    def programs(self, request: Request, pk: str | None = None) -> Response:
        return Response(control.programs(self.get_object()))

    @extend_schema(
        summary="The cobot's control commands, newest first",
        responses={200: CobotCommandSerializer(many=True), 404: CommandRefusalSerializer},
    )
    @action(detail=True, methods=["get"])
    def commands(self, request: Request, pk: str | None = None) -> Response:
        page: list[CobotCommand] = self.paginate_queryset(commands_of(self.get_object()))  # type: ignore[arg-type,assignment]
        return self.get_paginated_response(CobotCommandSerializer(page, many=True).data)


ADMINS_ONLY = "Only admins of the organisation set or delete its cobots' credentials."


class MembersReadAdminsWrite(MembersReadWritersWrite):
    """Members see the secrets' names (to choose one for a cobot); only admins write."""

    message = ADMINS_ONLY

    def has_permission(self, request: Request, view: Any) -> bool:
        return bool(request.user and request.user.is_authenticated)

    def has_object_permission(self, request: Request, view: Any, obj: Any) -> bool:
        if request.method in ("GET", "HEAD", "OPTIONS"):
            return True
        return is_admin_of(request.user, obj.organisation_id)


class CredentialsSecretViewSet(
    mixins.ListModelMixin,
    mixins.RetrieveModelMixin,
    mixins.DestroyModelMixin,
    viewsets.GenericViewSet[CredentialsSecret],
):
    """/api/cobot-credentials/: your organisations' credentials secrets, by name.

    POST sets one (creates it, or replaces the user name and password of the one
    of that name): admins of the organisation only. Nothing here ever returns a
    user name or password; another organisation's secret is 404.
    """

    serializer_class = CredentialsSecretSerializer
    permission_classes = [MembersReadAdminsWrite]

    def get_queryset(self) -> QuerySet[CredentialsSecret]:
        return (
            CredentialsSecret.objects.filter(organisation__in=organisations_of(self.request.user))
            .select_related("updated_by")
            .order_by("organisation_id", "name")
        )

    @extend_schema(
        request=SetCredentialsSecretSerializer,
        responses={201: CredentialsSecretSerializer, 200: CredentialsSecretSerializer},
    )
    def create(self, request: Request, *args: Any, **kwargs: Any) -> Response:
        body = SetCredentialsSecretSerializer(data=request.data)
        body.is_valid(raise_exception=True)
        organisation = _admin_organisation(request, body.validated_data.get("organisation"))
        name = body.validated_data["name"]
        existed = CredentialsSecret.objects.filter(organisation=organisation, name=name).exists()
        secret = services.set_credentials_secret(
            organisation,
            name,
            username=body.validated_data["username"],
            password=body.validated_data["password"],
            by=request.user,  # type: ignore[arg-type]  # authenticated: the permission
        )
        code = status.HTTP_200_OK if existed else status.HTTP_201_CREATED
        return Response(CredentialsSecretSerializer(secret).data, status=code)

    def perform_destroy(self, instance: CredentialsSecret) -> None:
        services.delete_credentials_secret(instance)


def _admin_organisation(request: Request, requested: int | None) -> Organisation:
    """The organisation a secret is set in: the requested one, or the user's only one as admin."""
    admin_of = memberships_of(request.user).filter(role=Role.ADMIN)
    if requested is not None:
        if not organisations_of(request.user).filter(pk=requested).exists():
            raise serializers.ValidationError(
                {"organisation": f"You are not a member of organisation {requested}."}
            )
        admin_of = admin_of.filter(organisation_id=requested)
    found = [m.organisation for m in admin_of[:2]]
    if not found:
        raise PermissionDenied(ADMINS_ONLY)
    if len(found) > 1:
        raise serializers.ValidationError(
            {"organisation": "You are an admin of several organisations: say which one (its id)."}
        )
    return found[0]


DEVICE_ADMINS_ONLY = "Only admins of the organisation register, change or deactivate its devices."


class MembersReadAdminsWriteDevices(MembersReadAdminsWrite):
    message = DEVICE_ADMINS_ONLY


class DeviceViewSet(
    mixins.ListModelMixin,
    mixins.RetrieveModelMixin,
    mixins.CreateModelMixin,
    mixins.UpdateModelMixin,
    viewsets.GenericViewSet[Device],
):
    """/api/devices/: the devices of your organisations' cells, each with a queue of its own.

    Members read; admins of the organisation register, change and deactivate
    (`is_active: false`) them. Another organisation's device is 404.
    """

    serializer_class = DeviceSerializer
    permission_classes = [MembersReadAdminsWriteDevices]

    def get_queryset(self) -> QuerySet[Device]:
        return devices_visible_to(self.request.user).order_by("name", "id")

    def perform_create(self, serializer: serializers.BaseSerializer[Device]) -> None:
        fields = dict(serializer.validated_data)
        requested = fields.pop("organisation", None)
        organisation = _admin_organisation(self.request, getattr(requested, "pk", requested))
        serializer.instance = services.create_device(organisation, **fields)

    def perform_update(self, serializer: serializers.BaseSerializer[Device]) -> None:
        assert serializer.instance is not None
        changes = dict(serializer.validated_data)
        changes.pop("organisation", None)  # validated to be unchanged
        services.update_device(serializer.instance, **changes)
