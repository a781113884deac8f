"""Fixtures of the analytics tests: a cobot and two published versions to run (running.py)."""

import pytest
from django.contrib.auth.models import User

from hrc.cobots.models import Cobot
from hrc.organisations.models import Organisation
from hrc.patterns import services as pattern_services
from hrc.patterns.models import PatternVersion
from tests import factories
from tests.cases.patterns import shared_space


@pytest.fixture
def cobot(organisation: Organisation) -> Cobot:
    return factories.make_cobot(organisation, name="ur5e-left")


@pytest.fixture
def hand_over(organisation: Organisation, engineer: User) -> PatternVersion:
    """The operator prepares (to1), then the cobot places (tc1); a time constraint to1 → tc1."""
    pattern = factories.make_pattern(organisation, name="Hand-over", created_by=engineer)
    return pattern_services.publish_pattern(pattern, published_by=engineer)


@pytest.fixture
def shared(organisation: Organisation, engineer: User) -> PatternVersion:
    """Load (to1); then the cobot picks (tc1) while the operator inspects (to2) in a shared
    area: a space constraint to2 → tc1 that pauses the cobot."""
    pattern = factories.make_pattern(
        organisation, name="Shared space", draft=shared_space(), created_by=engineer
    )
    return pattern_services.publish_pattern(pattern, published_by=engineer)
