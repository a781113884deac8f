"""The supervisor pages over HTTP: who may see them, and what they show.

Engineers and admins see their organisations' cases; an operator gets 403, an
outsider (an engineer of another organisation) 404 for our cases and none of
them in their lists. The browser tests (tests/browser/test_supervisor.py) do
the rest: the live marking and resolving incidents.
"""

import datetime as dt
import re
from pathlib import Path

import pytest
from django.conf import settings
from django.contrib.auth.models import User
from django.db.models import TextChoices
from django.test import Client
from django.utils import timezone
from pytest_django import DjangoAssertNumQueries

from hrc.cases import services
from hrc.cases.choices import CaseStatus, EventType, IncidentKind, InterruptionMode
from hrc.cases.models import Case, Incident, Interruption
from hrc.cases.views import EVENTS_PER_PAGE, format_duration, marking_change
from hrc.cobots.models import Cobot
from hrc.organisations.models import Organisation
from tests import factories

pytestmark = pytest.mark.django_db


def _client(user: User) -> Client:
    client = Client()
    client.force_login(user)
    return client


@pytest.fixture
def incident(step_case: Case) -> Incident:
    return factories.make_incident(factories.open_work_item(step_case, "tc1"), "Protective stop")


PAGES = ["/cases/", "/incidents/"]
SCRIPT = Path(settings.BASE_DIR) / "frontend" / "src" / "shared"


# Who may look ------------------------------------------------------------------------------


@pytest.mark.parametrize("url", [*PAGES, "/cases/{case}/"])
def test_a_visitor_who_is_not_signed_in_is_sent_to_sign_in(url: str, choice_case: Case) -> None:
    response = Client().get(url.format(case=choice_case.pk))
    assert response.status_code == 302
    assert response["Location"].startswith("/accounts/login/?next=")


@pytest.mark.parametrize("url", [*PAGES, "/cases/{case}/"])
def test_an_operator_is_refused_with_403_and_a_message(
    url: str, operator: User, choice_case: Case
) -> None:
    response = _client(operator).get(url.format(case=choice_case.pk))
    assert response.status_code == 403
    assert "Only engineers and admins" in response.content.decode()
    assert choice_case.version.pattern.name not in response.content.decode()


@pytest.mark.parametrize("url", PAGES)
def test_someone_in_no_organisation_is_refused_the_lists(url: str, loner: User) -> None:
    assert _client(loner).get(url).status_code == 403


def test_an_outsider_gets_404_for_our_case_and_none_of_ours_in_their_lists(
    outsider: User, other_organisation: Organisation, incident: Incident
) -> None:
    case = incident.case
    theirs = factories.make_case(
        factories.make_version(other_organisation, published_by=outsider),
        started_by=outsider,
        actor_mapping={"o": {"users": [outsider.pk]}, "c": {"cobot": _their_cobot(outsider)}},
    )
    client = _client(outsider)

    assert client.get(f"/cases/{case.pk}/").status_code == 404
    assert client.get(f"/cases/{case.pk}/?before=3").status_code == 404
    listed = client.get("/cases/?state=all").content.decode()
    assert f'data-case="{theirs.pk}"' in listed  # the positive control: their own case
    assert f'data-case="{case.pk}"' not in listed
    assert f'data-incident="{incident.pk}"' not in client.get("/incidents/").content.decode()


def _their_cobot(outsider: User) -> int:
    organisation = Organisation.objects.get(memberships__user=outsider)
    return factories.make_cobot(organisation).pk


@pytest.mark.parametrize("persona", ["engineer", "admin"])
def test_engineers_and_admins_see_every_page(
    persona: str, request: pytest.FixtureRequest, incident: Incident
) -> None:
    client = _client(request.getfixturevalue(persona))
    for url in [*PAGES, f"/cases/{incident.case_id}/"]:
        assert client.get(url).status_code == 200, url


# The list of cases -------------------------------------------------------------------------


def test_the_list_shows_pattern_version_state_current_tasks_and_open_incidents(
    engineer: User, incident: Incident, choice_case: Case
) -> None:
    page = _client(engineer).get("/cases/").content.decode()

    row = _row(page, incident.case_id)
    assert incident.case.version.pattern.name in row
    assert ">v1<" in row
    assert "Running" in row
    assert "place insert" in row  # the cobot step, offered to its cobot
    assert re.search(r'class="count nonzero">1<', row)
    other = _row(page, choice_case.pk)
    assert "count parts" in other
    assert re.search(r'class="count">0<', other)


def _row(page: str, case_id: int) -> str:
    match = re.search(rf'<tr data-case="{case_id}">(.*?)</tr>', page, re.S)
    assert match, f"case {case_id} is not listed"
    return match.group(1)


def test_the_list_shows_open_cases_unless_a_state_is_asked_for(
    engineer: User, choice_case: Case, step_case: Case
) -> None:
    services.cancel_case(choice_case, by=engineer)
    client = _client(engineer)

    default = client.get("/cases/").content.decode()
    assert f'data-case="{step_case.pk}"' in default
    assert f'data-case="{choice_case.pk}"' not in default
    cancelled = client.get("/cases/?state=cancelled").content.decode()
    assert f'data-case="{choice_case.pk}"' in cancelled
    assert f'data-case="{step_case.pk}"' not in cancelled
    every = client.get("/cases/?state=all").content.decode()
    assert f'data-case="{choice_case.pk}"' in every
    assert f'data-case="{step_case.pk}"' in every


def test_an_unknown_state_is_a_400_naming_the_states(engineer: User) -> None:
    response = _client(engineer).get("/cases/?state=paused")
    assert response.status_code == 400
    text = response.content.decode()
    assert "state must be one of open, running, suspended" in text
    assert "&#x27;paused&#x27;" in text


def test_the_list_costs_the_same_queries_for_one_case_or_many(
    engineer: User,
    operator: User,
    choice_case: Case,
    django_assert_max_num_queries: DjangoAssertNumQueries,
) -> None:
    client = _client(engineer)
    client.get("/cases/")  # sessions, content types: first-request costs
    with django_assert_max_num_queries(50) as one:
        client.get("/cases/")
    for _ in range(5):
        factories.make_case(
            choice_case.version, started_by=engineer, actor_mapping={"o": {"users": [operator.pk]}}
        )
    with django_assert_max_num_queries(len(one.captured_queries)):
        assert client.get("/cases/").content.decode().count("count parts") == 6


# One case ----------------------------------------------------------------------------------


def test_the_case_page_draws_the_net_with_the_marking_and_running_tasks(
    engineer: User, operator: User, choice_case: Case
) -> None:
    services.start_work_item(factories.open_work_item(choice_case, "count"), user=operator)
    page = _client(engineer).get(f"/cases/{choice_case.pk}/").content.decode()

    assert "<svg" in page
    for place in ("p1", "p2", "p3"):
        assert re.search(rf'data-place="{place}" data-tokens="0"', page), place
    assert 'data-task="count" data-state="running"' in page
    assert 'data-task="fix" data-state=""' in page
    assert "count parts" in page


def test_the_case_page_marks_offered_tasks_and_tokens(engineer: User, choice_case: Case) -> None:
    page = _client(engineer).get(f"/cases/{choice_case.pk}/").content.decode()
    assert 'data-place="p1" data-tokens="1"' in page
    assert 'data-task="count" data-state="offered"' in page


def test_the_case_page_marks_a_task_with_an_open_incident_and_offers_to_resolve_it(
    engineer: User, incident: Incident
) -> None:
    page = _client(engineer).get(f"/cases/{incident.case_id}/").content.decode()
    assert 'data-task="tc1" data-state="incident"' in page
    card = _incident_card(page, incident.pk)
    assert "Protective stop" in card
    assert "Cobot step failed" in card
    assert "&quot;RobotMode&quot;: 7" in card
    for resolution in ("retry", "skip", "cancel"):
        assert f'data-resolution="{resolution}"' in card


def _incident_card(page: str, incident_id: int) -> str:
    match = re.search(
        rf'<article class="incident[^"]*" data-incident="{incident_id}"(.*?)</article>', page, re.S
    )
    assert match, f"incident {incident_id} is not shown"
    return match.group(1)


def test_a_resolved_incident_shows_its_resolution(engineer: User, incident: Incident) -> None:
    services.resolve_incident(incident, by=engineer, resolution="skip", outputs={"placed": True})
    page = _client(engineer).get(f"/cases/{incident.case_id}/").content.decode()
    assert f'class="incident resolved" data-incident="{incident.pk}"' in page
    assert "Resolved: skip by erik-engineer" in _incident_card(page, incident.pk)
    assert "&quot;placed&quot;: true" in page  # the case data the skip gave
    assert 'data-place="p3" data-tokens="1"' in page


def test_the_timeline_lists_who_did_what_newest_first_with_the_marking_change(
    engineer: User, operator: User, choice_case: Case
) -> None:
    services.start_work_item(factories.open_work_item(choice_case, "count"), user=operator)
    page = _client(engineer).get(f"/cases/{choice_case.pk}/").content.decode()

    rows = re.findall(r'<tr data-seq="(\d+)" data-type="([a-z-]+)">(.*?)</tr>', page, re.S)
    assert [(int(seq), kind) for seq, kind, _ in rows] == [
        (3, "task-started"),
        (2, "task-offered"),
        (1, "case-started"),
    ]
    started = rows[0][2]
    assert "olivia-operator" in started
    assert "count parts" in started
    assert "p1 −1, running:count +1" in started
    assert "erik-engineer" in next(row for _, kind, row in rows if kind == "case-started")


def test_a_long_timeline_is_paged_and_costs_no_more_queries(
    engineer: User,
    operator: User,
    choice_case: Case,
    django_assert_max_num_queries: DjangoAssertNumQueries,
) -> None:
    client = _client(engineer)
    client.get(f"/cases/{choice_case.pk}/")
    with django_assert_max_num_queries(50) as short:
        client.get(f"/cases/{choice_case.pk}/")
    item = factories.open_work_item(choice_case, "count")
    for _ in range(40):  # two events each
        services.claim_work_item(item, user=operator)
        services.unclaim_work_item(item, user=operator)
    choice_case.refresh_from_db()
    last = choice_case.last_seq
    assert last > 2 * EVENTS_PER_PAGE - 20

    with django_assert_max_num_queries(len(short.captured_queries)):
        newest = client.get(f"/cases/{choice_case.pk}/").content.decode()
    seqs = [int(s) for s in re.findall(r'<tr data-seq="(\d+)"', newest)]
    assert seqs == list(range(last, last - EVENTS_PER_PAGE, -1))
    older = last - EVENTS_PER_PAGE + 1
    assert f'href="?before={older}"' in newest

    second = client.get(f"/cases/{choice_case.pk}/?before={older}").content.decode()
    seqs = [int(s) for s in re.findall(r'<tr data-seq="(\d+)"', second)]
    assert seqs == list(range(older - 1, max(older - 1 - EVENTS_PER_PAGE, 0), -1))
    assert 'href="?">Newest events' in second


@pytest.mark.parametrize("before", ["x", "-1", "1.5", "9999999999"])
def test_a_bad_timeline_page_is_a_400(engineer: User, choice_case: Case, before: str) -> None:
    response = _client(engineer).get(f"/cases/{choice_case.pk}/", {"before": before})
    assert response.status_code == 400
    assert "before must be an event number" in response.content.decode()


def test_interruptions_are_listed_with_their_durations(
    engineer: User, operator: User, step_case: Case, cobot: Cobot
) -> None:
    # Rows as jobs.py writes them for a space constraint (no service makes one on demand).
    step = factories.open_work_item(step_case, "tc1")
    operator_item = step_case.work_items.get(task="to1")
    began = timezone.now() - dt.timedelta(seconds=75)
    over = Interruption.objects.create(
        case=step_case, work_item=step, by_work_item=operator_item, cobot=cobot,
        mode=InterruptionMode.PAUSE,
    )  # fmt: skip
    Interruption.objects.filter(pk=over.pk).update(
        started_at=began, ended_at=began + dt.timedelta(seconds=12.5)
    )
    ongoing = Interruption.objects.create(
        case=step_case, work_item=step, by_work_item=operator_item, cobot=cobot,
        mode=InterruptionMode.SLOW,
    )  # fmt: skip
    Interruption.objects.filter(pk=ongoing.pk).update(started_at=began)

    page = _client(engineer).get(f"/cases/{step_case.pk}/").content.decode()
    section = page[page.index('id="interruptions"') : page.index('id="timeline"')]
    assert "12.5 s" in section
    assert re.search(r"1 min 1\d s <strong>\(ongoing\)</strong>", section)
    assert "Pause" in section
    assert "Slow down" in section
    assert "prepare workpiece" in section
    assert cobot.name in section


def test_the_open_tasks_say_where_a_cobot_job_stands(
    engineer: User, operator: User, cobot: Cobot, step_case: Case
) -> None:
    behind = factories.hand_over_case(
        step_case.version, started_by=engineer, operator=operator, cobot=cobot
    )  # its step waits for step_case's, which the cobot was free to take
    for case, where in ((step_case, "running"), (behind, "queued, position 1")):
        page = _client(engineer).get(f"/cases/{case.pk}/").content.decode()
        section = page[page.index('id="work-items"') : page.index('id="case-data"')]
        assert "place insert" in section
        assert where in section


# Open incidents ----------------------------------------------------------------------------


def test_the_incidents_page_lists_open_incidents_with_their_case(
    engineer: User, incident: Incident, choice_case: Case
) -> None:
    other = factories.make_incident(factories.open_work_item(choice_case, "count"), "No parts")
    services.resolve_incident(other, by=engineer, resolution="cancel")

    page = _client(engineer).get("/incidents/").content.decode()
    card = _incident_card(page, incident.pk)
    assert f'href="/cases/{incident.case_id}/"' in card
    assert incident.case.version.pattern.name in card
    assert f'data-incident="{other.pk}"' not in page
    assert 'id="supervisor-page"' in page


# The page script --------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("table", "choices"),
    [("EVENT_TYPES", EventType), ("INCIDENT_KINDS", IncidentKind), ("CASE_STATUSES", CaseStatus)],
)
def test_the_page_script_names_things_as_the_server_does(
    table: str, choices: type[TextChoices]
) -> None:
    source = (SCRIPT / "choices.ts").read_text()
    body = re.search(rf"export const {table}: Record<string, string> = {{(.*?)}};", source, re.S)
    assert body, table
    pairs = re.findall(r'"?([a-z-]+)"?: "([^"]+)"', body.group(1))
    assert dict(pairs) == dict(choices.choices)


# Helpers -----------------------------------------------------------------------------------


def test_marking_change_lists_each_place_that_changed() -> None:
    assert marking_change({"p1": 1, "q": 2}, {"p2": 1, "q": 2, "running:t": 1}) == [
        "p1 −1",
        "p2 +1",
        "running:t +1",
    ]


@pytest.mark.parametrize(
    ("seconds", "text"),
    [(0.04, "0.0 s"), (12.34, "12.3 s"), (65, "1 min 05 s"), (7380, "2 h 03 min")],
)
def test_format_duration(seconds: float, text: str) -> None:
    assert format_duration(seconds) == text


def test_a_finished_case_shows_its_status(engineer: User, choice_case: Case) -> None:
    services.cancel_case(choice_case, by=engineer)
    page = _client(engineer).get(f"/cases/{choice_case.pk}/").content.decode()
    assert 'id="case-status" class="status cancelled"' in page
    assert CaseStatus.CANCELLED.label in page
