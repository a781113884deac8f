import pytest
from django.core.exceptions import ValidationError

from hrc.cobots import services
from hrc.cobots.models import Cobot
from hrc.organisations.models import Organisation
from tests import factories


def test_cobot_names_are_unique_within_an_organisation_only(
    organisation: Organisation, other_organisation: Organisation
) -> None:
    factories.make_cobot(organisation, name="cobot1")
    factories.make_cobot(other_organisation, name="cobot1")
    with pytest.raises(ValidationError):
        factories.make_cobot(organisation, name="cobot1")
    assert Cobot.objects.filter(name="cobot1").count() == 2


def test_a_secret_in_the_credentials_source_is_refused(organisation: Organisation) -> None:
    with pytest.raises(ValidationError):
        factories.make_cobot(organisation, credentials_source="s3cr3t-password")
    assert not Cobot.objects.exists()


def test_update_validates_like_create(organisation: Organisation) -> None:
    cobot = factories.make_cobot(organisation)
    with pytest.raises(ValidationError):
        services.update_cobot(cobot, endpoint="http://nope")
    cobot.refresh_from_db()
    assert cobot.endpoint.startswith("opc.tcp://")


def test_the_organisation_of_a_cobot_is_not_editable(
    organisation: Organisation, other_organisation: Organisation
) -> None:
    cobot = factories.make_cobot(organisation)
    with pytest.raises(TypeError):
        services.update_cobot(cobot, organisation=other_organisation)
