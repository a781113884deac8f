"""A timer cancels an operator's task while the operator works beside a cobot it paused, at the
operator's tablet in a real browser: the cobot stays paused until the operator presses "I have
left the area" on the cancelled task, which then leaves the tablet."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest
from django.contrib.auth.models import User
from playwright.sync_api import Browser, ViewportSize, expect

from hrc.cases import jobs, timers
from hrc.cases import services as case_services
from hrc.cases.choices import InterruptionMode, WorkItemState
from hrc.cases.models import CaseTimer, Interruption, WorkItem
from hrc.cobots.models import Cobot
from hrc.organisations.models import Organisation
from tests import factories
from tests.cases import patterns
from tests.live.server import LiveServer

pytestmark = pytest.mark.django_db(transaction=True)


@pytest.fixture
def server(tmp_path: Path, transactional_db: None) -> Iterator[LiveServer]:
    running = LiveServer(tmp_path / "server.log").start()
    yield running
    running.stop()


def test_the_operator_says_they_have_left_and_the_paused_cobot_may_go_on(
    server: LiveServer, browser: Browser, organisation: Organisation, engineer: User,
    operator: User, cobot: Cobot,
) -> None:  # fmt: skip
    version = factories.make_version(
        organisation, published_by=engineer, draft=patterns.inspection_beside_cobot_with_deadline()
    )
    # Time scale 0: the deadline is due at once; this test rings it (no worker runs here).
    case = case_services.start_case(
        version, started_by=engineer, timer_scale=0,
        actor_mapping={"o": {"users": [operator.pk]}, "c": {"cobot": cobot.pk}},
    )  # fmt: skip
    assert jobs.lease_next_job(cobot.pk) is not None  # the pick runs on the cobot
    inspect = factories.open_work_item(case, "to2")
    page = browser.new_context(viewport=ViewportSize(width=1280, height=800)).new_page()
    page.goto(f"{server.url}/accounts/login/")
    page.get_by_label("User name").fill(operator.get_username())
    page.get_by_label("Password").fill(factories.PASSWORD)
    page.get_by_role("button", name="Sign in").click()
    page.wait_for_url(lambda landed: "/accounts/login/" not in landed)
    page.goto(f"{server.url}/tablet/")
    card = page.locator(f'.card[data-item="{inspect.pk}"]')
    card.get_by_role("button", name="Start").click()
    expect(card).to_have_attribute("data-state", "running")
    [pause] = Interruption.objects.filter(case=case, by_work_item=inspect)
    assert pause.mode == InterruptionMode.PAUSE

    assert timers.ring_timer(CaseTimer.objects.get(case=case, transition="late").pk)

    expect(card).to_have_attribute("data-state", "cancelled")
    expect(card).to_contain_text("A cobot stays paused until you have left the shared area")
    pause.refresh_from_db()
    assert pause.ended_at is None
    card.get_by_role("button", name="I have left the area").click()
    expect(card).to_have_count(0)
    pause.refresh_from_db()
    assert pause.ended_at is not None
    assert WorkItem.objects.get(pk=inspect.pk).state == WorkItemState.CANCELLED
