"""Cobots of your organisations: members read, engineers and admins write."""

from django.db.models import QuerySet
from rest_framework import serializers, viewsets

from hrc.api.permissions import MembersReadWritersWrite, target_organisation
from hrc.cobots import services
from hrc.cobots.api.serializers import CobotSerializer
from hrc.cobots.models import Cobot
from hrc.cobots.selectors import cobots_visible_to


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
