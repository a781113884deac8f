"""How the administration's people, teams, cells and record look over the API.

Team and member ids are plain integers here; the views look them up inside the
organisation, so another organisation's id is refused at its field.
"""

from __future__ import annotations

from typing import Any

from django.db.models import QuerySet
from drf_spectacular.types import OpenApiTypes
from drf_spectacular.utils import extend_schema_field
from rest_framework import serializers

from hrc.organisations.choices import Role
from hrc.organisations.models import AdminRecord, Cell, Membership, Organisation, Team
from hrc.organisations.selectors import admin_organisations_of


@extend_schema_field(OpenApiTypes.INT)
class AdminOrganisationField(serializers.PrimaryKeyRelatedField[Organisation]):
    """An organisation the requesting user is an admin of; any other id does not exist."""

    def get_queryset(self) -> QuerySet[Organisation]:
        request = self.context["request"]
        return admin_organisations_of(request.user)


class MemberSerializer(serializers.Serializer[Membership]):
    id = serializers.IntegerField(read_only=True)
    organisation = AdminOrganisationField()
    username = serializers.CharField(max_length=150)
    name = serializers.CharField(max_length=150, required=False, allow_blank=True)
    email = serializers.EmailField(required=False, allow_blank=True)
    role = serializers.ChoiceField(choices=Role.choices)
    teams = serializers.ListField(child=serializers.IntegerField(), required=False)
    is_active = serializers.BooleanField(read_only=True)
    # True: answer with an invitation link (they choose their password) instead of a password.
    invite = serializers.BooleanField(required=False, default=False, write_only=True)

    def to_representation(self, instance: Membership) -> dict[str, Any]:
        return {
            "id": instance.pk,
            "organisation": instance.organisation_id,
            "username": instance.user.username,
            "name": instance.user.get_full_name(),
            "email": instance.user.email,
            "role": instance.role,
            "teams": sorted(team.pk for team in instance.teams.all()),
            "is_active": instance.is_active,
        }


class MemberChangeSerializer(serializers.Serializer[Membership]):
    role = serializers.ChoiceField(choices=Role.choices, required=False)
    teams = serializers.ListField(child=serializers.IntegerField(), required=False)


class TeamSerializer(serializers.ModelSerializer[Team]):
    organisation = AdminOrganisationField()
    members = serializers.ListField(child=serializers.IntegerField(), required=False)

    class Meta:
        model = Team
        fields = ["id", "organisation", "name", "members"]
        validators: list[Any] = []  # the service checks the name is free, at its field

    def to_representation(self, instance: Team) -> dict[str, Any]:
        return {
            "id": instance.pk,
            "organisation": instance.organisation_id,
            "name": instance.name,
            "members": sorted(m.pk for m in instance.members.all()),
        }


class CellSerializer(serializers.ModelSerializer[Cell]):
    organisation = AdminOrganisationField()

    class Meta:
        model = Cell
        fields = ["id", "organisation", "name", "description"]
        validators: list[Any] = []  # the service checks the name is free, at its field

    def to_representation(self, instance: Cell) -> dict[str, Any]:
        return {
            "id": instance.pk,
            "organisation": instance.organisation_id,
            "name": instance.name,
            "description": instance.description,
        }


class AdminRecordSerializer(serializers.ModelSerializer[AdminRecord]):
    actor: serializers.SlugRelatedField[Any] = serializers.SlugRelatedField(
        slug_field="username", read_only=True
    )

    class Meta:
        model = AdminRecord
        fields = ["id", "organisation", "actor", "action", "target", "detail", "at"]
        read_only_fields = fields
