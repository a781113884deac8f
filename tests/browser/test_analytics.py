"""The analytics pages in a real browser: an engineer goes from the case list to a case's
Gantt chart, then to its version's figures, and downloads the event log as XES through the
ASGI server (the streamed download); operators and outsiders are kept out.

The cases run through the services and the worker's functions in this process
(tests/analytics/running.py) and are committed, so the server process sees them.
"""

from collections.abc import Callable
from pathlib import Path

import pytest
from django.contrib.auth.models import User
from playwright.sync_api import Page, expect

from hrc.cases.models import Case, WorkItem
from hrc.organisations.models import Organisation
from hrc.patterns import services as pattern_services
from tests import factories
from tests.analytics.running import pin, pin_interruption, run_hand_over, run_shared_space
from tests.analytics.xes_structure import NS, check_xes
from tests.browser.conftest import assert_fits
from tests.cases.patterns import shared_space

pytestmark = pytest.mark.django_db(transaction=True)

SignIn = Callable[[Page, User], None]
Screenshot = Callable[[Page, str], Path]


@pytest.fixture
def cases(organisation: Organisation, engineer: User, operator: User) -> list[Case]:
    """Two shared-space cases of one version (the second with two interruptions' worth of
    waiting) and a running hand-over whose cobot step is under way."""
    cobot = factories.make_cobot(organisation, name="ur5e-left")
    pattern = factories.make_pattern(
        organisation, name="Shared space", draft=shared_space(), created_by=engineer
    )
    version = pattern_services.publish_pattern(pattern, published_by=engineer)
    first = run_shared_space(version, engineer, operator, cobot)
    pin(first, started=0, ended=95,
        items={"to1": (0, 8, 20), "tc1": (20, 24, 95), "to2": (20, 40, 70)},
        jobs_={"tc1": (20, 24, 95)})  # fmt: skip
    pin_interruption(first, 40, 70)
    second = run_shared_space(version, engineer, operator, cobot)
    pin(second, started=120, ended=260,
        items={"to1": (120, 150, 170), "tc1": (170, 172, 260), "to2": (170, 200, 215)},
        jobs_={"tc1": (170, 172, 260)})  # fmt: skip
    pin_interruption(second, 200, 215)
    hand_over = factories.make_version(organisation, published_by=engineer)
    running = run_hand_over(hand_over, engineer, operator, cobot, finish=False)
    return [first, second, running]


def test_an_engineer_reads_a_cases_gantt_chart_then_its_versions_figures_and_log(
    page: Page,
    live_url: str,
    engineer: User,
    cases: list[Case],
    sign_in: SignIn,
    screenshot: Screenshot,
    tmp_path: Path,
) -> None:
    first = cases[0]
    sign_in(page, engineer)
    page.goto(f"{live_url}/cases/?state=all")
    page.locator(f'tr[data-case="{first.pk}"]').get_by_role("link", name="Gantt").click()

    chart = page.locator("svg.gantt")
    expect(chart).to_be_visible()
    expect(chart.locator("g.row")).to_have_count(2)
    items = {i.task: i.pk for i in WorkItem.objects.filter(case=first)}
    for task in ("to1", "tc1", "to2"):
        bar = chart.locator(f'g.bar[data-task="{task}"]')
        expect(bar).to_have_attribute("data-state", "completed")
        expect(bar.locator("rect.work")).to_be_visible()
    arrow = chart.locator("path.arrow.space")
    expect(arrow).to_have_count(1)
    expect(arrow).to_have_attribute("data-from", str(items["to2"]))
    expect(arrow).to_have_attribute("data-to", str(items["tc1"]))
    mark = chart.locator("g.interruption.pause")
    expect(mark).to_have_attribute("data-work-item", str(items["tc1"]))
    # The pause (40–70 s of 95 s) lies on the pick's bar (24–95 s), inside it.
    pick = chart.locator('g.bar[data-task="tc1"] rect.work').bounding_box()
    pause = mark.locator("rect").bounding_box()
    assert pick is not None
    assert pause is not None
    assert pick["x"] < pause["x"] < pause["x"] + pause["width"] < pick["x"] + pick["width"]
    assert pause["width"] == pytest.approx(pick["width"] * 30 / 71, rel=0.05)
    expect(page.locator("#bars tbody tr")).to_have_count(3)
    screenshot(page, "analytics-gantt")

    page.get_by_role("link", name="Analytics of v1").click()
    expect(page.locator("h1")).to_contain_text("Shared space")
    cycle = page.locator('tr[data-figure="cycle"] td')
    expect(cycle.nth(0)).to_have_text("2")  # both cases completed
    expect(cycle.nth(2)).to_have_text("1 min 57 s")  # p50 of 95 s and 140 s
    expect(page.locator("#tasks tbody tr")).to_have_count(3)
    expect(page.locator("#cobots .utilisation")).to_have_text("61.2 %")  # (71 + 88) / 260 s
    expect(page.locator("#interruptions")).to_contain_text("pause 2")
    screenshot(page, "analytics-version")

    with page.expect_download() as download_info:
        page.get_by_role("link", name="Download the event log (XES)").click()
    download = download_info.value
    assert download.suggested_filename == "shared-space-v1.xes"
    path = tmp_path / "log.xes"
    download.save_as(path)
    root = check_xes(path.read_bytes())
    traces = root.findall(f"{NS}trace")
    assert len(traces) == 2
    assert all(len(trace.findall(f"{NS}event")) == 6 for trace in traces)


def test_the_analytics_list_leads_to_each_version(
    page: Page,
    live_url: str,
    admin: User,
    cases: list[Case],
    sign_in: SignIn,
    screenshot: Screenshot,
) -> None:
    sign_in(page, admin)
    page.goto(f"{live_url}/analytics/")
    rows = page.locator("table.versions tbody tr")
    expect(rows).to_have_count(2)
    expect(rows.first).to_contain_text("Shared space")
    rows.nth(1).get_by_role("link").click()
    expect(page.locator("#cobots td").first).to_have_text("ur5e-left")
    expect(page.locator("#recent-cases tbody tr")).to_have_count(1)  # the running hand-over
    page.get_by_role("link", name="Gantt chart").click()
    expect(page.locator("svg.gantt g.now")).to_be_visible()  # the case still runs
    expect(page.locator('svg.gantt g.bar[data-task="tc1"]')).to_have_attribute(
        "data-state", "running"
    )
    screenshot(page, "analytics-gantt-running")


def test_operators_get_403_and_outsiders_404(
    page: Page,
    live_url: str,
    operator: User,
    outsider: User,
    cases: list[Case],
    sign_in: SignIn,
) -> None:
    sign_in(page, operator)
    response = page.goto(f"{live_url}/analytics/cases/{cases[0].pk}/gantt/")
    assert response is not None
    assert response.status == 403
    expect(page.get_by_role("alert")).to_contain_text("Only engineers and admins")
    page.context.clear_cookies()
    sign_in(page, outsider)
    response = page.goto(f"{live_url}/analytics/versions/{cases[0].version_id}/")
    assert response is not None
    assert response.status == 404
    download = page.request.get(f"{live_url}/api/analytics/xes/?case={cases[0].pk}")
    assert download.status == 404


def test_a_long_bar_breaks_the_axis_and_the_short_bars_stay_readable(
    page: Page,
    live_url: str,
    organisation: Organisation,
    engineer: User,
    operator: User,
    sign_in: SignIn,
    screenshot: Screenshot,
) -> None:
    cobot = factories.make_cobot(organisation, name="ur5e-left")
    pattern = factories.make_pattern(
        organisation, name="Shared space", draft=shared_space(), created_by=engineer
    )
    version = pattern_services.publish_pattern(pattern, published_by=engineer)
    case = run_shared_space(version, engineer, operator, cobot)
    # The pick takes an hour; the operator's two tasks take 12 and 30 seconds.
    pin(case, started=0, ended=3660,
        items={"to1": (0, 8, 20), "tc1": (20, 24, 3624), "to2": (20, 40, 70)},
        jobs_={"tc1": (20, 24, 3624)})  # fmt: skip
    pin_interruption(case, 40, 70)
    page.set_viewport_size({"width": 1280, "height": 800})
    sign_in(page, engineer)
    page.goto(f"{live_url}/analytics/cases/{case.pk}/gantt/")

    chart = page.locator("svg.gantt")
    gap = chart.locator("g.axis-break")
    expect(gap).to_have_count(1)
    expect(gap).to_have_attribute("data-hidden", "3554")  # from 70 s, to2's end, to 3624 s
    expect(gap.locator("text")).to_have_text("⋯ 59 min ⋯")
    short = chart.locator('g.bar[data-task="to1"] rect.work').bounding_box()
    long = chart.locator('g.bar[data-task="tc1"] rect.work').bounding_box()
    marker = gap.locator("rect").bounding_box()
    assert short is not None
    assert long is not None
    assert marker is not None
    assert short["width"] > 40  # 12 s of 3660: under 3 px on a linear axis
    assert long["width"] > short["width"]
    assert long["x"] < marker["x"] < long["x"] + long["width"]  # the break cuts the long bar
    expect(chart.locator('g.bar[data-task="to1"] text.label')).to_be_visible()
    screenshot(page, "analytics-gantt-broken-axis")
    assert_fits(page)
