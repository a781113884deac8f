"""/api/members/, /api/teams/, /api/cells/ and /api/admin-records/: the administration over REST.

Members of an organisation read its people, teams and cells; only its admins
change them (403 for the others) and read its record. Another organisation's
objects are not there (404, empty lists). Every write goes through
hrc.organisations.services, which records it.
"""

from __future__ import annotations

from typing import Any

from django.contrib.auth.models import User
from django.core.exceptions import ValidationError as DjangoValidationError
from django.db.models import QuerySet
from django.urls import reverse
from drf_spectacular.utils import extend_schema
from rest_framework import mixins, status, viewsets
from rest_framework.decorators import action
from rest_framework.exceptions import PermissionDenied, ValidationError
from rest_framework.request import Request
from rest_framework.response import Response

from hrc.organisations import services
from hrc.organisations.api.admin_serializers import (
    AdminRecordSerializer,
    CellSerializer,
    MemberChangeSerializer,
    MemberSerializer,
    TeamSerializer,
)
from hrc.organisations.models import AdminRecord, Cell, Membership, Organisation, Team
from hrc.organisations.selectors import admin_organisations_of, is_admin_of, organisations_of

ADMINS_ONLY = "Only the organisation's admins may change its people, teams and cells."


def _user(request: Request) -> User:
    assert isinstance(request.user, User)  # IsAuthenticated ran first
    return request.user


def _check_admin(request: Request, organisation_id: int) -> None:
    if not is_admin_of(request.user, organisation_id):
        raise PermissionDenied(ADMINS_ONLY)


def _teams(organisation: Organisation, ids: list[int]) -> list[Team]:
    teams = list(Team.objects.filter(organisation=organisation, pk__in=ids))
    missing = sorted(set(ids) - {team.pk for team in teams})
    if missing:
        raise ValidationError({"teams": [f"No team {i} in {organisation}." for i in missing]})
    return teams


def _members(organisation: Organisation, ids: list[int]) -> list[Membership]:
    found = Membership.objects.filter(organisation=organisation, is_active=True, pk__in=ids)
    members = list(found.select_related("user"))
    missing = sorted(set(ids) - {m.pk for m in members})
    if missing:
        raise ValidationError({"members": [f"No active member {i} in {organisation}." for i in missing]})  # fmt: skip
    return members


def _refused(error: DjangoValidationError) -> ValidationError:
    return ValidationError(error.message_dict if hasattr(error, "error_dict") else error.messages)


class _AdminsWrite:
    """Writes to an object need its organisation's admin; creating needs the named one's."""

    def check_object_permissions(self, request: Request, obj: Any) -> None:
        super().check_object_permissions(request, obj)  # type: ignore[misc]
        if request.method not in ("GET", "HEAD", "OPTIONS"):
            _check_admin(request, obj.organisation_id)

    def _organisation_to_create_in(self, request: Request) -> None:
        """403 for anyone who is no admin, or only a plain member of the organisation named;
        an organisation they are not in is left to the field ("does not exist")."""
        if not admin_organisations_of(request.user).exists():
            raise PermissionDenied(ADMINS_ONLY)
        wanted = request.data.get("organisation") if hasattr(request.data, "get") else None
        if isinstance(wanted, str) and wanted.isascii() and wanted.isdigit():
            wanted = int(wanted)
        if isinstance(wanted, int) and organisations_of(request.user).filter(pk=wanted).exists():
            _check_admin(request, wanted)


class MemberViewSet(
    _AdminsWrite,
    mixins.ListModelMixin,
    mixins.RetrieveModelMixin,
    mixins.CreateModelMixin,
    viewsets.GenericViewSet[Membership],
):
    """People of your organisations. Creating answers with their one-time password (or, with
    `invite`, their invitation link), once."""

    serializer_class = MemberSerializer

    def get_queryset(self) -> QuerySet[Membership]:
        return (
            Membership.objects.filter(organisation__in=organisations_of(self.request.user))
            .select_related("user")
            .prefetch_related("teams")
            .order_by("organisation_id", "user__username")
        )

    def create(self, request: Request, *args: Any, **kwargs: Any) -> Response:
        self._organisation_to_create_in(request)
        serializer = MemberSerializer(data=request.data, context={"request": request})
        serializer.is_valid(raise_exception=True)
        data = dict(serializer.validated_data)
        organisation = data.pop("organisation")
        data["teams"] = _teams(organisation, data.get("teams", []))
        try:
            membership, password = services.add_person(organisation, by=_user(request), **data)
        except DjangoValidationError as error:
            raise _refused(error) from None
        if password:
            body = MemberSerializer(membership).data | {"password": password}
        else:
            link = reverse("organisation:join", args=services.invitation_for(membership.user))
            body = MemberSerializer(membership).data | {"invitation": request.build_absolute_uri(link)}  # fmt: skip
        return Response(body, status=status.HTTP_201_CREATED)

    @extend_schema(request=MemberChangeSerializer, responses=MemberSerializer)
    def partial_update(self, request: Request, pk: str) -> Response:
        """Changes the member's role and/or teams."""
        membership = self.get_object()
        serializer = MemberChangeSerializer(data=request.data)
        serializer.is_valid(raise_exception=True)
        data = serializer.validated_data
        teams = _teams(membership.organisation, data["teams"]) if "teams" in data else None
        try:
            if "role" in data and data["role"] != membership.role:
                services.change_member_role(membership, data["role"], by=_user(request))
            if teams is not None:
                services.set_member_teams(membership, teams, by=_user(request))
        except DjangoValidationError as error:
            raise _refused(error) from None
        return Response(MemberSerializer(self.get_object()).data)

    @extend_schema(request=None, responses=MemberSerializer)
    @action(detail=True, methods=["post"])
    def deactivate(self, request: Request, pk: str) -> Response:
        """Ends their work here; the tasks they hold go back to their candidates."""
        membership = self.get_object()
        try:
            handed_back = services.deactivate_member(membership, by=_user(request))
        except DjangoValidationError as error:
            raise _refused(error) from None
        return Response(MemberSerializer(membership).data | {"tasks_handed_back": handed_back})

    @extend_schema(request=None, responses=MemberSerializer)
    @action(detail=True, methods=["post"], url_path="reset-password")
    def reset_password(self, request: Request, pk: str) -> Response:
        """A new one-time password, in this answer only."""
        membership = self.get_object()
        try:
            password = services.reset_member_password(membership, by=_user(request))
        except DjangoValidationError as error:
            raise _refused(error) from None
        return Response(MemberSerializer(membership).data | {"password": password})


class TeamViewSet(_AdminsWrite, viewsets.ModelViewSet[Team]):
    """Teams of your organisations, with their members' ids."""

    serializer_class = TeamSerializer
    http_method_names = ["get", "post", "patch", "delete", "head", "options"]

    def get_queryset(self) -> QuerySet[Team]:
        return (
            Team.objects.filter(organisation__in=organisations_of(self.request.user))
            .prefetch_related("members")
            .order_by("organisation_id", "name")
        )

    def create(self, request: Request, *args: Any, **kwargs: Any) -> Response:
        self._organisation_to_create_in(request)
        serializer = self.get_serializer(data=request.data)
        serializer.is_valid(raise_exception=True)
        organisation = serializer.validated_data["organisation"]
        members = _members(organisation, serializer.validated_data.get("members", []))
        name = serializer.validated_data["name"]
        try:
            team = services.add_team(organisation, by=_user(request), name=name, members=members)
        except DjangoValidationError as error:
            raise _refused(error) from None
        return Response(TeamSerializer(team).data, status=status.HTTP_201_CREATED)

    def partial_update(self, request: Request, *args: Any, **kwargs: Any) -> Response:
        team = self.get_object()
        serializer = self.get_serializer(team, data=request.data, partial=True)
        serializer.is_valid(raise_exception=True)
        data = serializer.validated_data
        if "members" in data:
            members = _members(team.organisation, data["members"])
        else:
            members = list(team.members.all())
        name = data.get("name", team.name)
        try:
            services.change_team(team, by=_user(request), name=name, members=members)
        except DjangoValidationError as error:
            raise _refused(error) from None
        return Response(TeamSerializer(self.get_object()).data)

    def perform_destroy(self, instance: Team) -> None:
        services.remove_team(instance, by=_user(self.request))


class CellViewSet(_AdminsWrite, viewsets.ModelViewSet[Cell]):
    """Cells of your organisations. A cell's name is its tablet's address; only its description changes."""

    serializer_class = CellSerializer
    http_method_names = ["get", "post", "patch", "delete", "head", "options"]
    # Digits only, so /api/cells/stop/ and /api/cells/resume/ (hrc.live) still reach their views.
    lookup_value_regex = r"[0-9]+"

    def get_queryset(self) -> QuerySet[Cell]:
        return Cell.objects.filter(organisation__in=organisations_of(self.request.user)).order_by(
            "organisation_id", "name"
        )

    def create(self, request: Request, *args: Any, **kwargs: Any) -> Response:
        self._organisation_to_create_in(request)
        serializer = self.get_serializer(data=request.data)
        serializer.is_valid(raise_exception=True)
        data = dict(serializer.validated_data)
        organisation = data.pop("organisation")
        try:
            cell = services.add_cell(organisation, by=_user(request), **data)
        except DjangoValidationError as error:
            raise _refused(error) from None
        return Response(CellSerializer(cell).data, status=status.HTTP_201_CREATED)

    def partial_update(self, request: Request, *args: Any, **kwargs: Any) -> Response:
        cell = self.get_object()
        serializer = self.get_serializer(cell, data=request.data, partial=True)
        serializer.is_valid(raise_exception=True)  # first: it refuses a body that is no object
        if set(request.data) - {"description"}:
            raise ValidationError({"name": "Only a cell's description changes: its name is its tablet's address."})  # fmt: skip
        description = serializer.validated_data.get("description", cell.description)
        try:
            services.describe_cell(cell, by=_user(request), description=description)
        except DjangoValidationError as error:
            raise _refused(error) from None
        return Response(CellSerializer(self.get_object()).data)

    def perform_destroy(self, instance: Cell) -> None:
        try:
            services.remove_cell(instance, by=_user(self.request))
        except DjangoValidationError as error:
            raise _refused(error) from None


class AdminRecordViewSet(viewsets.ReadOnlyModelViewSet[AdminRecord]):
    """The administration record of the organisations you are an admin of, latest first."""

    serializer_class = AdminRecordSerializer

    def get_queryset(self) -> QuerySet[AdminRecord]:
        return AdminRecord.objects.filter(
            organisation__in=admin_organisations_of(self.request.user)
        ).select_related("actor")
