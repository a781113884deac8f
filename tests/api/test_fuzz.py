"""schemathesis over the OpenAPI schema (/api/schema/): no generated request gets a 5xx.

Every operation of the schema, with data that fits it and data that does not
(schemathesis' positive and negative modes), is sent to the real application
in process (its WSGI handler, on the test's PostgreSQL database) as nobody, as
an engineer and as an admin of one organisation. Ids in paths are generated,
and for half the cases they are those of real objects of that organisation,
so that requests get past the 404s. A fixed seed and example count make it the
same run every time; the test counts the requests it sent.

The test's transaction is never committed, so nothing queued on commit (a
cobot step for the worker, a broadcast) runs: no real work starts.
"""

from collections.abc import Iterator
from dataclasses import dataclass, field
from functools import cache
from typing import Any

import pytest
from django.conf import settings
from django.contrib.auth.models import User
from django.core.signals import request_finished, request_started
from django.db import close_old_connections
from django.test import Client
from hypothesis import HealthCheck, Phase, given, seed
from hypothesis import settings as hypothesis_settings
from hypothesis import strategies as st
from schemathesis import APIOperation, Case, GenerationMode, openapi
from schemathesis.checks import not_a_server_error
from schemathesis.core.result import Ok
from schemathesis.specs.openapi.schemas import OpenApiSchema

from hrc.cases.models import Case as RunningCase
from hrc.cases.models import Job, WorkItem
from hrc.cobots.models import Cobot
from hrc.organisations import services as organisation_services
from hrc.organisations.models import Membership, Organisation
from hrc.patterns.models import PatternModel, PatternVersion
from hrc.wsgi import application
from tests import factories

pytestmark = pytest.mark.django_db

Operation = APIOperation[Any, Any, Any, Any]
FuzzCase = Case[Any]

SEED = 17
# Examples per operation for each persona (positive and negative cases together): with the
# schema's 88 operations, 2,200 requests. Nobody's are all 401s, so fewer are enough.
EXAMPLES = {"nobody": 3, "engineer": 12, "admin": 10}
MIN_REQUESTS = 2000

# The operations that talk to a cobot's gateway. They never get the id of a real cobot, so
# the fuzzer drives no robot, and no request waits seconds for a gateway that is not there;
# what they get is the wall, the role and the body checks in front of the cobot.
GATEWAY_ACTIONS = {
    "power-on",
    "brake-release",
    "power-off",
    "program",
    "programs",
    "registers",
    "state",
}
# Django's CSRF check passes when the cookie and the header carry the same secret.
CSRF_SECRET = "fuzzfuzzfuzzfuzzfuzzfuzzfuzzfuzz"


@dataclass(frozen=True)
class Credentials:
    headers: dict[str, str] = field(default_factory=dict)
    cookies: dict[str, str] = field(default_factory=dict)


@dataclass
class Tally:
    """Requests sent, by persona and by status."""

    by_persona: dict[str, int] = field(default_factory=dict)
    by_status: dict[int, int] = field(default_factory=dict)

    def count(self, persona: str, status: int) -> None:
        self.by_persona[persona] = self.by_persona.get(persona, 0) + 1
        self.by_status[status] = self.by_status.get(status, 0) + 1

    @property
    def requests(self) -> int:
        return sum(self.by_persona.values())


@cache
def api_schema() -> OpenApiSchema:
    return openapi.from_wsgi("/api/schema/?format=json", application)


def operations() -> list[Operation]:
    """The schema's operations, deletions last (they take the real objects away)."""
    found = []
    for result in api_schema().get_all_operations():
        assert isinstance(result, Ok), result  # the schema itself is valid
        found.append(result.ok())
    return sorted(found, key=lambda operation: operation.method.upper() == "DELETE")


@pytest.fixture
def requests_keep_the_test_transaction() -> Iterator[None]:
    """Django closes the connection at each request's start and end when it is inside a
    transaction; Django's test client turns that off, and so must requests sent straight to
    the WSGI handler, or the first one would end the test's transaction."""
    request_started.disconnect(close_old_connections)
    request_finished.disconnect(close_old_connections)
    yield
    request_started.connect(close_old_connections)
    request_finished.connect(close_old_connections)


@pytest.fixture
def real_ids(
    organisation: Organisation,
    admin: User,
    operator: User,
    pattern: PatternModel,
    choice_version: PatternVersion,
    choice_case: RunningCase,
    step_case: RunningCase,
    cobot: Cobot,
) -> dict[str, int]:
    """A real object of the organisation for each path that takes an id, by what comes
    before its `{id}`. The member is the operator, not a persona: deactivating the persona
    would end the run's session."""
    item = WorkItem.objects.filter(case=choice_case).first()
    job = Job.objects.filter(case=step_case).first()
    assert item is not None
    assert job is not None
    incident = factories.make_incident(item)
    team = organisation_services.create_team(organisation, name="Line 1")
    cell = organisation_services.add_cell(organisation, by=admin, name="cell-1")
    record = organisation.admin_records.first()  # adding the cell recorded one
    assert record is not None
    return {
        "/api/organisations/": organisation.pk,
        "/api/members/": Membership.objects.get(user=operator, organisation=organisation).pk,
        "/api/teams/": team.pk,
        "/api/cells/": cell.pk,
        "/api/admin-records/": record.pk,
        "/api/patterns/": pattern.pk,
        "/api/pattern-versions/": choice_version.pk,
        "/api/analytics/versions/": choice_version.pk,
        "/api/cases/": choice_case.pk,
        "/api/analytics/cases/": choice_case.pk,
        "/api/work-items/": item.pk,
        "/api/incidents/": incident.pk,
        "/api/jobs/": job.pk,
        "/api/cobots/": cobot.pk,
    }


def signed_in(user: User) -> Credentials:
    """The session of a signed-in browser, with a CSRF cookie and header that agree."""
    client = Client()
    client.force_login(user)
    session = client.cookies[settings.SESSION_COOKIE_NAME].value
    return Credentials(
        headers={"X-CSRFToken": CSRF_SECRET},
        cookies={settings.SESSION_COOKIE_NAME: session, settings.CSRF_COOKIE_NAME: CSRF_SECRET},
    )


def reaches_the_gateway(operation: Operation) -> bool:
    before_id, _, after_id = operation.path.partition("{id}")
    return before_id == "/api/cobots/" and after_id.strip("/").split("/")[0] in GATEWAY_ACTIONS


def path_id(case: FuzzCase) -> int | None:
    """The id the case puts in its path, when it is one (negative cases write anything)."""
    written = str(case.path_parameters.get("id", ""))
    return int(written) if written.isascii() and written.isdigit() and len(written) <= 18 else None


def names_no_cobot(case: FuzzCase) -> bool:
    return not Cobot.objects.filter(pk=path_id(case) or 0).exists()


def cases_for(
    operation: Operation, real_ids: dict[str, int], personas: set[int]
) -> st.SearchStrategy[FuzzCase]:
    """Positive and negative cases of the operation, half of them about a real object.

    None touches the personas' memberships (`personas`): a persona deactivated, demoted or
    given a new password by a generated id would be refused everything after."""
    generated = st.one_of([operation.as_strategy(generation_mode=mode) for mode in GenerationMode])
    if reaches_the_gateway(operation):
        return generated.filter(names_no_cobot)
    if operation.path.startswith("/api/members/{id}"):
        generated = generated.filter(lambda case: path_id(case) not in personas)
    real = real_ids.get(operation.path.partition("{id}")[0])
    if "{id}" not in operation.path or real is None:
        return generated
    about_real = st.one_of(
        [
            operation.as_strategy(generation_mode=mode, path_parameters={"id": real})
            for mode in GenerationMode
        ]
    )
    return st.one_of(generated, about_real)


def fuzz(
    operation: Operation,
    cases: st.SearchStrategy[FuzzCase],
    persona: str,
    credentials: Credentials,
    tally: Tally,
) -> None:
    """Sends EXAMPLES[persona] cases of the operation; fails at the first 5xx."""

    @seed(SEED)
    @hypothesis_settings(
        max_examples=EXAMPLES[persona],
        database=None,  # the same run every time, and no .hypothesis/ directory
        deadline=None,
        phases=[Phase.generate],  # no shrinking: the failing case is reported as found
        suppress_health_check=list(HealthCheck),
    )
    @given(case=cases)
    def send(case: FuzzCase) -> None:
        response = case.call(headers=credentials.headers, cookies=credentials.cookies)
        tally.count(persona, response.status_code)
        try:
            case.validate_response(response, checks=[not_a_server_error])
        except BaseException as failure:
            failure.add_note(f"As {persona}: {case.as_curl_command()}")
            raise

    send()


def test_no_generated_request_gets_a_server_error(
    engineer: User,
    admin: User,
    real_ids: dict[str, int],
    requests_keep_the_test_transaction: None,
) -> None:
    personas = {"nobody": Credentials(), "engineer": signed_in(engineer), "admin": signed_in(admin)}
    memberships = set(
        Membership.objects.filter(user__in=[engineer, admin]).values_list("pk", flat=True)
    )
    tally = Tally()
    for operation in operations():
        cases = cases_for(operation, real_ids, memberships)
        for persona, credentials in personas.items():
            fuzz(operation, cases, persona, credentials, tally)
    assert tally.requests >= MIN_REQUESTS, tally
    # The members stayed signed in (nobody's requests are the 401s), and got answers.
    assert tally.by_status.get(401, 0) <= 1.1 * tally.by_persona["nobody"], tally
    assert tally.by_status.get(200, 0) > 0.2 * tally.requests, tally
