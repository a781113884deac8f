"""The analytics pages over HTTP: who may see them, and what they show (the SVG chart's bars,
arrows and marks; the version's tables)."""

import re

import pytest
from django.contrib.auth.models import User
from django.test import Client

from hrc.cases.models import Case, WorkItem
from hrc.cobots.models import Cobot
from hrc.organisations.models import Organisation
from hrc.patterns.models import PatternVersion
from tests import factories
from tests.analytics.running import pin, pin_interruption, run_shared_space

pytestmark = pytest.mark.django_db

PAGES = ["/analytics/", "/analytics/versions/{version}/", "/analytics/cases/{case}/gantt/"]


def signed_in(user: User) -> Client:
    client = Client()
    client.force_login(user)
    return client


@pytest.fixture
def case(shared: PatternVersion, engineer: User, operator: User, cobot: Cobot) -> Case:
    case = run_shared_space(shared, engineer, operator, cobot)
    pin(case, started=0, ended=60,
        items={"to1": (0, 2, 5), "tc1": (5, 6, 60), "to2": (5, 10, 35)},
        jobs_={"tc1": (5, 6, 60)})  # fmt: skip
    pin_interruption(case, 10, 35)
    return case


def page(client: Client, url: str, case: Case) -> str:
    response = client.get(url.format(version=case.version_id, case=case.pk))
    assert response.status_code == 200
    return response.content.decode()


# Who may look ------------------------------------------------------------------------------


@pytest.mark.parametrize("url", PAGES)
def test_a_visitor_who_is_not_signed_in_is_sent_to_sign_in(url: str, case: Case) -> None:
    response = Client().get(url.format(version=case.version_id, case=case.pk))
    assert response.status_code == 302
    assert response["Location"].startswith("/accounts/login/?next=")


@pytest.mark.parametrize("url", PAGES)
def test_an_operator_is_refused_with_403_and_a_message(
    url: str, operator: User, case: Case
) -> None:
    response = signed_in(operator).get(url.format(version=case.version_id, case=case.pk))
    assert response.status_code == 403
    assert "Only engineers and admins" in response.content.decode()
    assert "Shared space" not in response.content.decode()


def test_an_outsider_gets_404_for_our_pages_and_none_of_our_versions(
    outsider: User, other_organisation: Organisation, case: Case
) -> None:
    theirs = factories.make_version(other_organisation, published_by=outsider)
    client = signed_in(outsider)
    assert client.get(f"/analytics/versions/{case.version_id}/").status_code == 404
    assert client.get(f"/analytics/cases/{case.pk}/gantt/").status_code == 404
    listed = client.get("/analytics/").content.decode()
    assert f'data-version="{theirs.pk}"' in listed  # the positive control: their own version
    assert f'data-version="{case.version_id}"' not in listed


def test_someone_in_no_organisation_is_refused_the_list(loner: User) -> None:
    assert signed_in(loner).get("/analytics/").status_code == 403


@pytest.mark.parametrize("persona", ["engineer", "admin"])
def test_engineers_and_admins_see_every_page(
    persona: str, request: pytest.FixtureRequest, case: Case
) -> None:
    client = signed_in(request.getfixturevalue(persona))
    for url in PAGES:
        assert "Shared space" in page(client, url, case)


# The Gantt chart ---------------------------------------------------------------------------


def test_the_gantt_chart_draws_a_bar_per_task_an_arrow_per_constraint_and_the_interruption(
    engineer: User, case: Case
) -> None:
    html = page(signed_in(engineer), "/analytics/cases/{case}/gantt/", case)
    svg = html[html.index("<svg") : html.index("</svg>")]
    items = {i.task: i.pk for i in WorkItem.objects.filter(case=case)}
    assert re.findall(r'class="row (\w+)" data-actor="(\w+)"', svg) == [
        ("cobot", "c"),
        ("operator", "o"),
    ]
    bars = re.findall(r'data-work-item="(\d+)" data-task="(\w+)" data-state="(\w+)"', svg)
    assert sorted(bars) == sorted(
        (str(items[task]), task, "completed") for task in ("to1", "tc1", "to2")
    )
    arrows = re.findall(r'class="arrow (\w+)" data-constraint="(\d+)"[^>]*'
                        r'data-from="(\d+)" data-to="(\d+)"', svg)  # fmt: skip
    assert arrows == [("space", "0", str(items["to2"]), str(items["tc1"]))]
    marks = re.findall(r'class="interruption (\w+)" data-interruption="\d+" '
                       r'data-work-item="(\d+)"', svg)  # fmt: skip
    assert marks == [("pause", str(items["tc1"]))]
    to2 = WorkItem.objects.get(case=case, task="to2")
    assert f"paused: {to2.label} (o) in the shared area</title>" in svg
    assert 'class="now"' not in svg  # the case has ended
    assert "1:00" in svg  # the axis reaches the case's minute
    assert 'href="/api/analytics/xes/?case=' in html


def test_the_gantt_page_lists_the_constraints_with_their_arrows_and_the_bars_as_a_table(
    engineer: User, case: Case
) -> None:
    html = page(signed_in(engineer), "/analytics/cases/{case}/gantt/", case)
    table = html[html.index('id="constraints"') :]
    assert re.search(
        r'data-constraint="0"><td>0</td><td>space</td>.*?<td class="num">1</td>', table
    )
    bars = html[html.index('id="bars"') :]
    assert re.search(
        r"inspect <code[^>]*>to2</code>.*?olivia-operator.*?5\.0 s.*?25\.0 s", bars, re.S
    )


def test_the_case_page_and_the_case_list_link_to_the_gantt_chart(
    engineer: User, case: Case
) -> None:
    client = signed_in(engineer)
    gantt = f'href="/analytics/cases/{case.pk}/gantt/"'
    assert gantt in client.get(f"/cases/{case.pk}/").content.decode()
    assert gantt in client.get("/cases/?state=all").content.decode()


# A version's page --------------------------------------------------------------------------


def test_the_version_page_shows_cycle_times_tasks_cobots_and_interruptions(
    engineer: User, case: Case, cobot: Cobot
) -> None:
    html = page(signed_in(engineer), "/analytics/versions/{version}/", case)
    cycle = html[html.index('data-figure="cycle"') :]
    assert re.match(r'data-figure="cycle"><th scope="row">[^<]*</th><td class="num">1</td>'
                    r'<td class="num">1 min 00 s</td>', cycle)  # fmt: skip
    tasks = re.findall(r'<tr data-task="(\w+)">', html)
    assert tasks == ["to1", "tc1", "to2"]
    cobot_row = html[html.index(f'data-cobot="{cobot.pk}"') :]
    assert re.search(r"ur5e-left</td><td class=\"num\">1</td><td class=\"num\">54\.0 s</td>"
                     r"<td class=\"num\">1 min 00 s</td>", cobot_row)  # fmt: skip
    assert '<span class="utilisation">90.0 %</span>' in cobot_row
    stops = html[html.index('id="interruptions"') :]
    assert "pause 1" in stops
    assert "25.0 s" in stops
    assert f'href="/analytics/cases/{case.pk}/gantt/"' in html
    assert f'href="/api/analytics/xes/?version={case.version_id}"' in html


def test_a_bad_window_on_the_version_page_is_a_400_that_names_it(
    engineer: User, case: Case
) -> None:
    response = signed_in(engineer).get(f"/analytics/versions/{case.version_id}/?since=soon")
    assert response.status_code == 400
    assert "since must be a date and time" in response.content.decode()


def test_the_version_page_narrows_to_a_window_and_its_download_follows(
    engineer: User, case: Case
) -> None:
    client = signed_in(engineer)
    html = client.get(
        f"/analytics/versions/{case.version_id}/?since=2025-03-01T09:00&until="
    ).content.decode()
    assert "No cases started in this window." in html
    assert "since=2025-03-01T09%3A00%3A00%2B00%3A00" in html
