"""How cobots look over the API. Credentials appear only as their source, never as a secret."""

from rest_framework import serializers

from hrc.cobots.models import Cobot
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
