"""The timers a case waits for, on an operator's tablet in a real browser: "waiting until
HH:MM:SS (label)" appears when the case arms the timer and goes when it fires, from the live
deltas alone (the page is not reloaded)."""

from __future__ import annotations

import datetime as dt
from collections.abc import Iterator
from pathlib import Path

import pytest
from django.contrib.auth.models import User
from playwright.sync_api import Browser, ViewportSize, expect

from hrc.cases import services as case_services
from hrc.cases import timers
from hrc.cases.models import CaseTimer
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


def test_the_tablet_shows_the_timer_a_case_waits_for_until_it_fires(
    server: LiveServer, browser: Browser, organisation: Organisation, engineer: User,
    operator: User,
) -> None:  # fmt: skip
    version = factories.make_version(
        organisation, published_by=engineer, draft=patterns.inspection_with_deadline()
    )
    context = browser.new_context(viewport=ViewportSize(width=1280, height=800), timezone_id="UTC")
    page = context.new_page()
    page.goto(f"{server.url}/accounts/login/")
    page.get_by_label("User name").fill(operator.get_username())
    page.get_by_label("Password").fill(factories.PASSWORD)
    page.get_by_role("button", name="Sign in").click()
    page.wait_for_url(lambda landed: "/accounts/login/" not in landed)
    page.goto(f"{server.url}/tablet/")
    expect(page.locator(".connection")).to_have_text("Live")
    waiting = page.locator(".waiting")
    expect(waiting).to_be_hidden()

    # Time scale 0: the deadline is due at once; this test rings it (no worker runs here).
    case = case_services.start_case(
        version, started_by=engineer, timer_scale=0,
        actor_mapping={"o": {"users": [operator.pk]}},
    )  # fmt: skip
    timer = CaseTimer.objects.get(case=case, transition="late")
    line = f"waiting until {timer.due_at.astimezone(dt.UTC):%H:%M:%S} (inspection late)"
    inspect = factories.open_work_item(case, "to1")
    card = page.locator(f'.card[data-item="{inspect.pk}"]')
    expect(card.locator(".timer")).to_have_text(line)
    expect(waiting).to_be_visible()
    expect(waiting.locator(f'li[data-case="{case.pk}"]')).to_contain_text(line)

    assert timers.ring_timer(timer.pk)

    rework = factories.open_work_item(case, "to_rework")
    expect(page.locator(f'.card[data-item="{rework.pk}"]')).to_be_visible()
    expect(card).to_have_count(0)
    expect(page.locator(".timer")).to_have_count(0)
    expect(waiting).to_be_hidden()
