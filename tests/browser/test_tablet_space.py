"""Two operators sharing an area, at their tablets in a real browser (daphne serving the page and
its socket): the second one's Start is refused with the task in the area and who does it, and
goes through once the first has completed."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from django.contrib.auth.models import User
from playwright.sync_api import Browser, Page, ViewportSize, expect

from hrc.cases import services as case_services
from hrc.cases.choices import InterruptionMode
from hrc.cases.models import Interruption, WorkItem
from hrc.organisations.choices import Role
from hrc.organisations.models import Organisation
from tests import factories
from tests.live.server import LiveServer

pytestmark = pytest.mark.django_db(transaction=True)


def _side_by_side() -> dict[str, Any]:
    """Olivia inspects the left side (to1) while Paul inspects the right (to2), in one area."""
    return {
        "format": "hrc-pattern/1",
        "name": "Two inspectors",
        "actors": [{"id": "o1", "type": "operator"}, {"id": "o2", "type": "operator"}],
        "processes": [{
            "id": "N", "workpiece": "w", "actors": ["o1", "o2"],
            "places": [{"id": p, "tokens": 1 if p == "p0" else 0} for p in ("p0", "p1", "p2", "p3", "p4", "p5")],
            "transitions": [
                {"id": "split"}, {"id": "join"},
                {"id": "to1", "performer": "o1", "label": "Inspect the left side"},
                {"id": "to2", "performer": "o2", "label": "Inspect the right side"},
            ],
            "arcs": [["p0", "split"], ["split", "p1"], ["split", "p2"], ["p1", "to1"], ["to1", "p3"],
                     ["p2", "to2"], ["to2", "p4"], ["p3", "join"], ["p4", "join"], ["join", "p5"]],
        }],
        "constraints": [{"from": "to1", "to": "to2", "type": "space"}],
    }  # fmt: skip


@pytest.fixture
def server(tmp_path: Path, transactional_db: None) -> Iterator[LiveServer]:
    running = LiveServer(tmp_path / "server.log").start()
    yield running
    running.stop()


def _tablet_of(browser: Browser, url: str, user: User) -> Page:
    page = browser.new_context(viewport=ViewportSize(width=1280, height=800)).new_page()
    page.goto(f"{url}/accounts/login/")
    page.get_by_label("User name").fill(user.get_username())
    page.get_by_label("Password").fill(factories.PASSWORD)
    page.get_by_role("button", name="Sign in").click()
    page.wait_for_url(lambda landed: "/accounts/login/" not in landed)
    page.goto(f"{url}/tablet/")
    return page


def test_the_second_operator_is_told_who_is_in_the_area_and_may_start_after(
    server: LiveServer, browser: Browser, organisation: Organisation, engineer: User
) -> None:
    olivia = factories.make_member(organisation, Role.OPERATOR, "olivia")
    paul = factories.make_member(organisation, Role.OPERATOR, "paul")
    version = factories.make_version(organisation, published_by=engineer, draft=_side_by_side())
    case = case_services.start_case(
        version, started_by=None,
        actor_mapping={"o1": {"users": [olivia.pk]}, "o2": {"users": [paul.pk]}},
    )  # fmt: skip
    left, right = (WorkItem.objects.get(case=case, task=task) for task in ("to1", "to2"))
    hers, his = _tablet_of(browser, server.url, olivia), _tablet_of(browser, server.url, paul)
    her_card = hers.locator(f'.card[data-item="{left.pk}"]')
    his_card = his.locator(f'.card[data-item="{right.pk}"]')

    her_card.get_by_role("button", name="Start").click()
    expect(her_card).to_have_attribute("data-state", "running")
    his_card.get_by_role("button", name="Start").click()

    alert = his.get_by_role("alert")
    expect(alert).to_contain_text("Inspect the left side (olivia) is in the shared area")
    expect(his_card).to_have_attribute("data-state", "offered")
    [refusal] = Interruption.objects.filter(case=case)
    assert (refusal.work_item_id, refusal.by_work_item_id) == (right.pk, left.pk)
    assert refusal.mode == InterruptionMode.REFUSED

    her_card.get_by_role("button", name="Complete…").click()
    hers.locator(".form-dialog").get_by_role("button", name="Complete").click()
    expect(her_card).to_have_count(0)
    his_card.get_by_role("button", name="Start").click()
    expect(his_card).to_have_attribute("data-state", "running")
    refusal.refresh_from_db()
    assert refusal.ended_at is not None
