"""A case's interruptions (space constraints at run time): read by its organisation's members."""

import datetime as dt

import pytest
from django.utils import timezone
from rest_framework.test import APIClient

from hrc.cases.choices import InterruptionMode
from hrc.cases.models import Case, Interruption
from hrc.cobots.models import Cobot
from tests import factories

pytestmark = pytest.mark.django_db


@pytest.fixture
def interruptions(step_case: Case, cobot: Cobot) -> list[Interruption]:
    """One that lasted 12.5 s, then one still under way (the operator is in the area)."""
    step = factories.open_work_item(step_case, "tc1")
    operator_item = step_case.work_items.get(task="to1")
    began = timezone.now() - dt.timedelta(seconds=75)
    made = [
        Interruption.objects.create(
            case=step_case, work_item=step, by_work_item=operator_item, cobot=cobot, mode=mode
        )
        for mode in (InterruptionMode.PAUSE, InterruptionMode.SLOW)
    ]
    Interruption.objects.filter(pk=made[0].pk).update(
        started_at=began, ended_at=began + dt.timedelta(seconds=12.5),
        paused_at=began, resumed_at=began + dt.timedelta(seconds=13),
    )  # fmt: skip
    Interruption.objects.filter(pk=made[1].pk).update(started_at=began + dt.timedelta(seconds=20))
    return made


def test_a_member_reads_the_interruptions_in_order_with_their_durations(
    operator_client: APIClient, step_case: Case, cobot: Cobot, interruptions: list[Interruption]
) -> None:
    response = operator_client.get(f"/api/cases/{step_case.pk}/interruptions/")
    assert response.status_code == 200, response.data
    rows = response.data["results"]
    assert [row["id"] for row in rows] == [i.pk for i in interruptions]
    over, ongoing = rows
    assert (over["task"], over["by_task"], over["cobot_name"]) == ("tc1", "to1", cobot.name)
    assert (over["actor"], over["by_actor"]) == ("c", "o")  # both pattern actors
    assert (over["mode"], over["seconds"], over["settled"]) == ("pause", 12.5, True)
    assert (ongoing["mode"], ongoing["seconds"], ongoing["settled"]) == ("slow", None, False)


def test_an_outsider_sees_no_interruptions_not_even_that_the_case_exists(
    outsider_client: APIClient, step_case: Case, interruptions: list[Interruption]
) -> None:
    response = outsider_client.get(f"/api/cases/{step_case.pk}/interruptions/")
    assert response.status_code == 404
    assert "detail" in response.data
