"""How a call activity finds the published pattern it calls: by name, within one organisation."""

from typing import Any

from django.contrib.auth.models import User

from hrc.engine import read_pattern
from hrc.organisations.models import Organisation
from hrc.patterns import services
from hrc.patterns.models import PatternModel, PatternVersion
from hrc.patterns.selectors import published_pattern_named
from tests import factories


def _titled(title: str) -> dict[str, Any]:
    """A valid, publishable document whose name tells the versions apart."""
    return {**factories.valid_document(), "name": title}


def _publish(pattern: PatternModel, title: str, engineer: User) -> PatternVersion:
    services.update_pattern(pattern, draft=_titled(title))
    return services.publish_pattern(pattern, published_by=engineer)


def test_the_latest_version_of_the_pattern_of_that_name_is_found_whatever_the_case(
    organisation: Organisation, engineer: User
) -> None:
    spot_tape = factories.make_pattern(organisation, name="SpotTape")
    _publish(spot_tape, "first", engineer)
    _publish(spot_tape, "second", engineer)

    found = published_pattern_named(organisation, ["spottape"])

    assert found == read_pattern(_titled("second"))


def test_the_first_name_that_finds_a_pattern_wins(
    organisation: Organisation, engineer: User
) -> None:
    _publish(factories.make_pattern(organisation, name="Sub_Step1Handshake"), "step", engineer)
    _publish(factories.make_pattern(organisation, name="Hand-over"), "hand-over", engineer)

    assert published_pattern_named(organisation, ["Process_7", "hand-over"]) == read_pattern(
        _titled("hand-over")
    )
    assert published_pattern_named(
        organisation, [" sub_step1handshake ", "Hand-over"]
    ) == read_pattern(_titled("step"))


def test_another_organisations_pattern_of_that_name_is_never_found(
    organisation: Organisation, other_organisation: Organisation, outsider: User
) -> None:
    theirs = factories.make_pattern(other_organisation, name="SpotTape")
    _publish(theirs, "theirs", outsider)

    assert published_pattern_named(organisation, ["SpotTape"]) is None
    assert published_pattern_named(other_organisation, ["SpotTape"]) is not None


def test_a_draft_never_published_or_a_retired_version_is_not_found(
    organisation: Organisation, engineer: User
) -> None:
    factories.make_pattern(organisation, name="Draft only")
    retired = factories.make_pattern(organisation, name="Retired")
    first = _publish(retired, "first", engineer)
    second = _publish(retired, "second", engineer)

    services.retire_version(second, retired=True)
    assert published_pattern_named(organisation, ["Retired"]) == read_pattern(_titled("first"))
    services.retire_version(first, retired=True)

    assert published_pattern_named(organisation, ["Draft only", "Retired", ""]) is None
