"""Organisations the signed-in user belongs to, and `me`: who am I and what may I do where."""

from django.db.models import QuerySet
from drf_spectacular.utils import extend_schema
from rest_framework import viewsets
from rest_framework.decorators import action
from rest_framework.request import Request
from rest_framework.response import Response

from hrc.organisations.api.serializers import MeSerializer, OrganisationSerializer
from hrc.organisations.models import Organisation
from hrc.organisations.selectors import memberships_of, organisations_of


class OrganisationViewSet(viewsets.ReadOnlyModelViewSet[Organisation]):
    """The organisations you are a member of; any other organisation is 404."""

    serializer_class = OrganisationSerializer

    def get_queryset(self) -> QuerySet[Organisation]:
        return organisations_of(self.request.user).order_by("name")

    @extend_schema(responses=MeSerializer)
    @action(detail=False, pagination_class=None)
    def me(self, request: Request) -> Response:
        """The signed-in user with each membership's organisation and role."""
        user = request.user
        data = {
            "id": user.pk,
            "username": user.get_username(),
            "memberships": memberships_of(user).order_by("organisation__name"),
        }
        return Response(MeSerializer(data).data)
