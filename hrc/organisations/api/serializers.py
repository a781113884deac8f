"""How organisations and memberships look over the API (read-only: admins use the admin site)."""

from django.db.models import QuerySet
from rest_framework import serializers

from hrc.organisations.models import Membership, Organisation
from hrc.organisations.selectors import organisations_of


class OrganisationSerializer(serializers.ModelSerializer[Organisation]):
    class Meta:
        model = Organisation
        fields = ["id", "name", "slug"]
        read_only_fields = fields


class MembershipSerializer(serializers.ModelSerializer[Membership]):
    organisation = OrganisationSerializer(read_only=True)

    class Meta:
        model = Membership
        fields = ["organisation", "role"]
        read_only_fields = fields


class MeSerializer(serializers.Serializer[object]):
    """The signed-in user and where they belong."""

    id = serializers.IntegerField(read_only=True)
    username = serializers.CharField(read_only=True)
    memberships = MembershipSerializer(many=True, read_only=True)


class MemberOrganisationField(serializers.PrimaryKeyRelatedField[Organisation]):
    """An organisation id among the requesting user's; any other id is 'does not exist'."""

    def get_queryset(self) -> QuerySet[Organisation]:
        request = self.context.get("request")
        user = getattr(request, "user", None)
        return organisations_of(user) if user is not None else Organisation.objects.none()
