"""GET /api/analytics/versions/{id}/: a version's cases measured, from cases run for real."""

import pytest
from django.contrib.auth.models import User
from django.db import connection
from django.test.utils import CaptureQueriesContext
from rest_framework.test import APIClient

from hrc.cases.models import Case
from hrc.cobots.models import Cobot
from hrc.patterns.models import PatternVersion
from tests.analytics.running import pin, pin_interruption, run_hand_over, run_shared_space

pytestmark = pytest.mark.django_db


def url(version: PatternVersion, query: str = "") -> str:
    return f"/api/analytics/versions/{version.pk}/{query}"


@pytest.fixture
def three_cases(
    hand_over: PatternVersion, engineer: User, operator: User, cobot: Cobot
) -> list[Case]:
    """Two completed hand-overs (cycle 100 s and 300 s) and one whose step still runs."""
    first = run_hand_over(hand_over, engineer, operator, cobot)
    pin(first, started=0, ended=100,
        items={"to1": (0, 10, 40), "tc1": (40, 50, 100)}, jobs_={"tc1": (40, 50, 100)})  # fmt: skip
    second = run_hand_over(hand_over, engineer, operator, cobot)
    pin(second, started=200, ended=500,
        items={"to1": (200, 230, 300), "tc1": (300, 340, 500)}, jobs_={"tc1": (300, 340, 500)})  # fmt: skip
    third = run_hand_over(hand_over, engineer, operator, cobot, finish=False)
    pin(third, started=900, ended=None,
        items={"to1": (900, 960, 970), "tc1": (970, 980, None)}, jobs_={"tc1": (970, 980, None)})  # fmt: skip
    return [first, second, third]


def test_cycle_times_per_case_and_per_task_with_percentiles(
    engineer_client: APIClient, hand_over: PatternVersion, three_cases: list[Case]
) -> None:
    response = engineer_client.get(url(hand_over))
    assert response.status_code == 200
    body = response.json()
    assert (body["version"], body["number"], body["cases"]) == (hand_over.pk, 1, 3)
    assert body["by_status"] == {"completed": 2, "running": 1}
    cycle = body["cycle"]
    assert (cycle["count"], cycle["min"], cycle["max"], cycle["mean"]) == (2, 100.0, 300.0, 200.0)
    assert (cycle["p50"], cycle["p90"], cycle["p99"]) == pytest.approx((200.0, 280.0, 298.0))
    assert [(c["id"], c["cycle_seconds"]) for c in body["recent_cases"]] == [
        (three_cases[2].pk, None),
        (three_cases[1].pk, 300.0),
        (three_cases[0].pk, 100.0),
    ]
    tasks = {t["task"]: t for t in body["tasks"]}
    assert [t["task"] for t in body["tasks"]] == ["to1", "tc1"]  # the document's order
    to1, tc1 = tasks["to1"], tasks["tc1"]
    assert (to1["label"], to1["kind"], to1["offered"], to1["completed"]) == (
        "prepare workpiece",
        "operator",
        3,
        3,
    )
    assert (to1["work"]["count"], to1["work"]["min"], to1["work"]["max"]) == (3, 10.0, 70.0)
    assert to1["work"]["p50"] == 30.0
    assert (to1["wait"]["min"], to1["wait"]["p50"], to1["wait"]["max"]) == (10.0, 30.0, 60.0)
    assert (tc1["kind"], tc1["completed"], tc1["work"]["count"], tc1["work"]["max"]) == (
        "step",
        2,
        2,
        160.0,
    )
    waiting = body["operator_waiting"]
    assert (waiting["count"], waiting["total"], waiting["p50"]) == (3, 100.0, 30.0)


def test_cobot_utilisation_is_its_busy_time_over_the_observed_window(
    engineer_client: APIClient, hand_over: PatternVersion, cobot: Cobot, three_cases: list[Case]
) -> None:
    body = engineer_client.get(url(hand_over)).json()
    (figures,) = body["cobots"]
    assert (figures["cobot"], figures["name"], figures["jobs"]) == (cobot.pk, "ur5e-left", 3)
    # The window runs from the first start (0 s) to now (the third case still runs): its
    # step has been busy since 980 s, so busy = 50 + 160 + (now - 980).
    window = figures["window_seconds"]
    assert window > 1000
    assert figures["busy_seconds"] == pytest.approx(50 + 160 + window - 980)
    assert figures["utilisation"] == pytest.approx(figures["busy_seconds"] / window)
    assert (figures["queue_wait"]["count"], figures["queue_wait"]["max"]) == (3, 40.0)
    assert body["window"]["start"] == "2025-03-01T08:00:00Z"


def test_interruptions_are_counted_and_timed(
    engineer_client: APIClient, shared: PatternVersion, engineer: User, operator: User, cobot: Cobot
) -> None:
    case = run_shared_space(shared, engineer, operator, cobot)
    pin_interruption(case, started=10, ended=34.5)
    body = engineer_client.get(url(shared)).json()
    stops = body["interruptions"]
    assert (stops["count"], stops["ongoing"], stops["by_mode"]) == (1, 0, {"pause": 1})
    assert stops["by_cobot"] == {"ur5e-left": 1}
    assert (stops["duration"]["count"], stops["duration"]["max"]) == (1, 24.5)
    assert body["recent_cases"][0]["interruptions"] == 1


def test_since_and_until_keep_the_cases_that_started_between(
    engineer_client: APIClient, hand_over: PatternVersion, three_cases: list[Case]
) -> None:
    body = engineer_client.get(
        url(hand_over, "?since=2025-03-01T08:01:00Z&until=2025-03-01T08:10:00%2B00:00")
    ).json()
    assert [c["id"] for c in body["recent_cases"]] == [three_cases[1].pk]
    assert body["since"] == "2025-03-01T08:01:00Z"
    assert body["cycle"]["count"] == 1
    everything_before = engineer_client.get(url(hand_over, "?until=2025-03-01")).json()
    assert everything_before["cases"] == 0
    assert everything_before["window"] is None


@pytest.mark.parametrize(
    ("query", "parameter", "words"),
    [
        ("?since=yesterday", "since", "since must be a date and time in ISO 8601"),
        ("?until=2025-13-01", "until", "until must be a date and time"),
        ("?since=2025-03-02&until=2025-03-01", "until", "until must come after since"),
        ("?since=2026-01-01T00:00:00%2B23:08", "since", "the UTC offset +23:08"),
        ("?until=2026-01-01T00:00:00-15:00", "until", "offsets lie within -14:00 and +14:00"),
        ("?until=9999-12-31T23:00:00-05:00", "until", "must lie between"),
    ],
)
def test_a_bad_window_is_a_400_that_names_the_parameter(
    engineer_client: APIClient, hand_over: PatternVersion, query: str, parameter: str, words: str
) -> None:
    response = engineer_client.get(url(hand_over, query))
    assert response.status_code == 400
    assert response.json()["parameter"] == parameter
    assert words in response.json()["detail"]


def test_a_version_without_cases_has_empty_figures(
    admin_client: APIClient, hand_over: PatternVersion
) -> None:
    body = admin_client.get(url(hand_over)).json()
    assert (body["cases"], body["cycle"]["count"], body["cycle"]["p50"]) == (0, 0, None)
    assert (body["tasks"], body["cobots"], body["recent_cases"]) == ([], [], [])


def test_the_figures_cost_the_same_few_queries_however_many_cases(
    engineer_client: APIClient,
    hand_over: PatternVersion,
    engineer: User,
    operator: User,
    cobot: Cobot,
) -> None:
    def queries() -> int:
        with CaptureQueriesContext(connection) as captured:
            assert engineer_client.get(url(hand_over)).status_code == 200
        return len(captured.captured_queries)

    run_hand_over(hand_over, engineer, operator, cobot)
    one = queries()
    for _ in range(3):
        run_hand_over(hand_over, engineer, operator, cobot)
    assert queries() == one
    # The version, the role, then cases, work items, jobs and interruptions: a query each.
    assert one <= 6, one
