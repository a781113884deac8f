"""Personas and API clients shared by the tests of the Django apps.

The home organisation has an operator, an engineer and an admin. The
outsider is an engineer of another organisation: able to write at home, so
a 404 on our objects shows the wall, not a missing role. The loner belongs
to no organisation. The cobot and the case waiting for it serve the runtime's
pages and API.
"""

import pytest
from django.contrib.auth.models import User
from django.test import Client
from rest_framework.test import APIClient

from hrc.cases.models import Case
from hrc.cobots.models import Cobot
from hrc.live import groups
from hrc.organisations import services as organisation_services
from hrc.organisations.choices import Role
from hrc.organisations.models import Organisation
from hrc.patterns.models import PatternModel, PatternVersion
from tests import factories


@pytest.hookimpl(tryfirst=True)
def pytest_runtest_teardown(item: pytest.Item) -> None:
    """Before a transactional test's database is emptied, the live sender has sent what the test
    queued. The sender reads the cobot queues on its own connection, cobots before jobs, while
    the flush truncates jobs before cobots: a read late enough to meet it deadlocks with it."""
    marker = item.get_closest_marker("django_db")
    transactional = marker is not None and marker.kwargs.get("transaction", False)
    fixtures = set(getattr(item, "fixturenames", ()))
    if transactional or {"transactional_db", "live_server"} & fixtures:
        groups.flush()


@pytest.fixture
def organisation(db: None) -> Organisation:
    return factories.make_organisation("Home plant")


@pytest.fixture
def other_organisation(db: None) -> Organisation:
    return factories.make_organisation("Other plant")


@pytest.fixture
def operator(organisation: Organisation) -> User:
    return factories.make_member(organisation, Role.OPERATOR, "olivia-operator")


@pytest.fixture
def engineer(organisation: Organisation) -> User:
    return factories.make_member(organisation, Role.ENGINEER, "erik-engineer")


@pytest.fixture
def admin(organisation: Organisation) -> User:
    return factories.make_member(organisation, Role.ADMIN, "ada-admin")


@pytest.fixture
def outsider(other_organisation: Organisation) -> User:
    return factories.make_member(other_organisation, Role.ENGINEER, "oscar-outsider")


@pytest.fixture
def loner(db: None) -> User:
    return factories.make_user("lena-loner")


def _client_for(user: User | None) -> APIClient:
    client = APIClient()
    if user is not None:
        client.force_authenticate(user)
    return client


@pytest.fixture
def operator_client(operator: User) -> APIClient:
    return _client_for(operator)


@pytest.fixture
def engineer_client(engineer: User) -> APIClient:
    return _client_for(engineer)


@pytest.fixture
def admin_client(admin: User) -> APIClient:
    return _client_for(admin)


@pytest.fixture
def outsider_client(outsider: User) -> APIClient:
    return _client_for(outsider)


@pytest.fixture
def loner_client(loner: User) -> APIClient:
    return _client_for(loner)


@pytest.fixture
def anonymous_client() -> APIClient:
    return _client_for(None)


@pytest.fixture
def pattern(organisation: Organisation, engineer: User) -> PatternModel:
    """A valid, sound, unpublished pattern of the home organisation."""
    return factories.make_pattern(organisation, name="Hand-over", created_by=engineer)


@pytest.fixture
def staff_client(db: None) -> Client:
    """A browser signed in to the Django admin as a superuser."""
    superuser = organisation_services.provision_user(
        "root", password="a-test-password", is_staff=True, is_superuser=True
    )
    client = Client()
    client.force_login(superuser)
    return client


@pytest.fixture
def choice_version(organisation: Organisation, engineer: User) -> PatternVersion:
    """A published operator-only pattern: count (with a form), then fix or rework."""
    return factories.make_version(
        organisation, published_by=engineer, draft=factories.choice_document()
    )


@pytest.fixture
def choice_case(choice_version: PatternVersion, engineer: User, operator: User) -> Case:
    """A running case of choice_version whose tasks are offered to the operator alone."""
    return factories.make_case(
        choice_version, started_by=engineer, actor_mapping={"o": {"users": [operator.pk]}}
    )


@pytest.fixture
def cobot(organisation: Organisation) -> Cobot:
    return factories.make_cobot(organisation)


@pytest.fixture
def step_case(organisation: Organisation, engineer: User, operator: User, cobot: Cobot) -> Case:
    """A hand-over case: the operator has prepared the workpiece, the cobot step is queued."""
    version = factories.make_version(organisation, published_by=engineer)
    return factories.hand_over_case(version, started_by=engineer, operator=operator, cobot=cobot)
