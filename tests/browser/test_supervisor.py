"""The supervisor pages in a real browser: an engineer follows a running case on its net and
timeline, and resolves incidents; others are kept out.

The server is a separate process (live_url), so everything a test sets up is
committed first. The retry test runs the step for real: a simulated cobot
(an OPC UA gateway process) goes into a protective stop, the person at the
cell unlocks it, the engineer presses Retry, and this process's job runner
(Simulation's inline workers and sweeper) drives the cobot to the end.
"""

import re
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
from django.contrib.auth.models import User
from playwright.sync_api import Page, expect

from hrc.cases import services
from hrc.cases.choices import CaseStatus, JobState
from hrc.cases.models import Case, Incident, Job
from hrc.cases.simulation import Simulation
from hrc.organisations.choices import Role
from tests import factories
from tests.cases.patterns import cobot_chain, shared_space
from tests.support.polling import until

pytestmark = pytest.mark.django_db(transaction=True)

SignIn = Callable[[Page, User], None]
Screenshot = Callable[[Page, str], Path]
# With its live socket up a page reads the API when a delta rings, and polls only every
# 30 s (frontend/src/supervisor/model.ts): a change shown within LIVE came by the socket.
LIVE = 10_000
# The cobot's steps run this many times slower until a test has done what must happen
# mid-step: a ~1 s pick could otherwise end first on a loaded machine (signing in takes time).
SLOWDOWN = "4"


def _card(page: Page, incident: Incident) -> Any:
    return page.locator(f'[data-incident="{incident.pk}"]')


def test_an_engineer_follows_a_running_case_on_its_net_and_timeline(
    page: Page,
    live_url: str,
    engineer: User,
    operator: User,
    choice_case: Case,
    sign_in: SignIn,
    screenshot: Screenshot,
) -> None:
    count = factories.open_work_item(choice_case, "count")
    services.start_work_item(count, user=operator)
    sign_in(page, engineer)

    page.goto(f"{live_url}/cases/")
    row = page.locator(f'tr[data-case="{choice_case.pk}"]')
    expect(row).to_contain_text("count parts")
    expect(row).to_contain_text("Running")
    screenshot(page, "supervisor-cases")
    row.get_by_role("link", name=f"case {choice_case.pk}").click()

    net = page.locator("svg.net")
    expect(net.locator('[data-task="count"]')).to_have_attribute("data-state", "running")
    expect(net.locator('[data-place="p1"]')).to_have_attribute("data-tokens", "0")
    timeline = page.locator("#timeline tbody tr")
    expect(timeline).to_have_count(3)
    expect(timeline.first).to_contain_text("Task started")
    expect(timeline.first).to_contain_text("olivia-operator")
    expect(timeline.first).to_contain_text("p1 −1, running:count +1")
    expect(page.locator("#live-status")).to_have_attribute("data-live", "socket")
    expect(page.locator("#live-status")).to_have_text("Live")
    screenshot(page, "supervisor-case-running")

    # The operator finishes on the shop floor; the open page follows by itself.
    services.complete_work_item(count, user=operator, data={"count": 3})

    expect(net.locator('[data-place="p2"]')).to_have_attribute("data-tokens", "1", timeout=LIVE)
    expect(net.locator('[data-place="p2"] .tokens')).to_have_text("●")
    expect(net.locator('[data-task="count"]')).to_have_attribute("data-state", "")
    expect(net.locator('[data-task="fix"]')).to_have_attribute("data-state", "offered")
    expect(net.locator('[data-task="rework"]')).to_have_attribute("data-state", "offered")
    expect(page.locator("#timeline tbody tr").first).to_contain_text("Task offered")
    expect(page.locator("#timeline tbody")).to_contain_text("Task completed")
    expect(page.locator("#case-data")).to_contain_text('"count": 3')
    expect(page.locator("#work-items")).to_contain_text("fix by hand")
    screenshot(page, "supervisor-case-moved-on")


def test_an_engineer_hands_a_started_task_to_a_colleague_when_its_operator_has_gone(
    page: Page,
    live_url: str,
    engineer: User,
    operator: User,
    choice_version: Any,
    sign_in: SignIn,
    screenshot: Screenshot,
) -> None:
    colleague = factories.make_member(engineer.memberships.get().organisation, Role.OPERATOR, "carl-colleague")  # fmt: skip
    mapping = {"o": {"users": [operator.pk, colleague.pk]}}
    case = factories.make_case(choice_version, started_by=engineer, actor_mapping=mapping)
    count = factories.open_work_item(case, "count")
    services.start_work_item(count, user=operator)
    sign_in(page, engineer)
    page.goto(f"{live_url}/cases/{case.pk}/")

    row = page.locator('#work-items tr[data-task="count"]')
    expect(row).to_contain_text("olivia-operator")
    row.get_by_role("button", name="Hand over…").click()
    dialog = page.locator("dialog#reassign")
    expect(dialog).to_be_visible()
    expect(dialog.locator("h3")).to_have_text("Hand over count parts")
    # A started task cannot go back to nobody, nor to the one who has it.
    expect(dialog.locator("option")).to_have_text(["carl-colleague"])
    screenshot(page, "supervisor-hand-over")
    dialog.get_by_role("button", name="Hand over").click()

    expect(dialog).to_be_hidden()
    expect(row).to_contain_text("carl-colleague", timeout=LIVE)
    expect(page.locator("#timeline tbody tr").first).to_contain_text("Task reassigned")
    count.refresh_from_db()
    assert (count.state, count.claimed_by) == ("running", colleague)


def test_an_engineer_skips_a_failed_step_with_its_outputs(
    page: Page,
    live_url: str,
    engineer: User,
    step_case: Case,
    sign_in: SignIn,
    screenshot: Screenshot,
) -> None:
    incident = factories.make_incident(factories.open_work_item(step_case, "tc1"), "Gripper lost")
    sign_in(page, engineer)
    page.goto(f"{live_url}/cases/{step_case.pk}/")
    expect(page.locator('svg.net [data-task="tc1"]')).to_have_attribute("data-state", "incident")
    card = _card(page, incident)
    expect(card).to_contain_text("Gripper lost")
    screenshot(page, "supervisor-case-incident")

    outputs = card.get_by_label("Outputs (JSON)")
    outputs.fill("{placed: true}")
    card.get_by_role("button", name="Skip with outputs").click()
    expect(card.get_by_role("alert")).to_contain_text("The outputs are not JSON")

    outputs.fill('{"placed": true}')
    card.get_by_role("button", name="Skip with outputs").click()

    expect(card.get_by_role("status")).to_have_text("Resolved: skip by erik-engineer")
    expect(card).to_have_class("incident resolved")
    expect(card.locator(".errors")).to_be_empty()
    expect(page.locator("#case-status")).to_have_text("Completed", timeout=LIVE)
    expect(page.locator('svg.net [data-place="p3"]')).to_have_attribute("data-tokens", "1")
    expect(page.locator('svg.net [data-task="tc1"]')).to_have_attribute("data-state", "")
    expect(page.locator("#case-data")).to_contain_text('"placed": true')
    expect(page.locator("#timeline tbody")).to_contain_text("Incident resolved")
    expect(page.locator("#timeline tbody")).to_contain_text("resolution: skip")
    screenshot(page, "supervisor-case-skipped")
    step_case.refresh_from_db()
    assert (step_case.status, step_case.data["tc1"]) == (CaseStatus.COMPLETED, {"placed": True})


def test_the_incidents_page_shows_new_incidents_and_the_apis_refusals(
    page: Page,
    live_url: str,
    engineer: User,
    choice_case: Case,
    step_case: Case,
    sign_in: SignIn,
    screenshot: Screenshot,
) -> None:
    first = factories.make_incident(factories.open_work_item(step_case, "tc1"), "Gripper lost")
    sign_in(page, engineer)
    page.goto(f"{live_url}/incidents/")
    expect(_card(page, first)).to_contain_text("Gripper lost")
    expect(page.locator("#live-status")).to_have_attribute("data-live", "socket")

    # An incident about an operator task opens while the page is open.
    later = factories.make_incident(factories.open_work_item(choice_case, "count"), "No parts")
    card = _card(page, later)
    expect(card).to_contain_text("No parts", timeout=LIVE)
    expect(page.locator(".incident").first).to_have_attribute("data-incident", str(later.pk))
    expect(card.get_by_role("link", name=f"case {choice_case.pk}")).to_be_visible()

    card.get_by_role("button", name="Retry").click()
    expect(card.get_by_role("alert")).to_have_text(
        "count parts is an operator task: there is nothing to retry."
    )
    screenshot(page, "supervisor-incidents-refused")

    card.get_by_role("button", name="Cancel the case").click()
    expect(card.get_by_role("status")).to_have_text("Resolved: cancel by erik-engineer")
    expect(card.locator(".errors")).to_be_empty()
    choice_case.refresh_from_db()
    assert choice_case.status == CaseStatus.CANCELLED

    # Resolved elsewhere: the card says so at the next poll.
    services.resolve_incident(first, by=engineer, resolution="cancel")
    expect(_card(page, first).get_by_role("status")).to_have_text(
        "Resolved: cancel by erik-engineer", timeout=LIVE
    )
    screenshot(page, "supervisor-incidents")


def test_an_engineer_retries_a_step_after_a_protective_stop_and_sees_the_case_finish(
    page: Page, live_url: str, sign_in: SignIn, screenshot: Screenshot, tmp_path: Path
) -> None:
    with Simulation(cobot_chain(steps=1, timeout=30), tmp_path, time_scale=0.5) as simulation:
        engineer = factories.make_member(simulation.organisation, Role.ENGINEER, "eve-engineer")
        cobot = simulation.cobot("c")
        cobot.call("Simulator/InjectFault", "slow-steps", SLOWDOWN)  # stopped mid-step, surely
        with simulation.running(operators=False):
            [case_id] = simulation.start_cases(1)
            case = Case.objects.get(pk=case_id)
            load = until(lambda: case.work_items.filter(task="to1").first())
            services.start_work_item(load, user=simulation.users["o"])
            services.complete_work_item(load, user=simulation.users["o"])
            until(lambda: Job.objects.filter(case=case, state=JobState.RUNNING).exists())
            cobot.call("Simulator/InjectFault", "protective-stop", "")
            incident = until(lambda: Incident.objects.filter(case=case).first())
            cobot.call("Simulator/ClearFault")  # the slowdown; the stop stays for a person

            sign_in(page, engineer)
            page.goto(f"{live_url}/cases/{case_id}/")
            card = _card(page, incident)
            expect(card).to_contain_text("PROTECTIVE_STOP")
            expect(card.locator("details pre")).to_contain_text("SAFETY_MODE_PROTECTIVE_STOP")
            expect(page.locator('svg.net [data-task="tc1"]')).to_have_attribute(
                "data-state", "incident"
            )
            screenshot(page, "supervisor-protective-stop")

            # The person at the cell clears the stop (hrc never does); then the engineer retries.
            until(lambda: _unlocked(cobot))
            card.get_by_role("button", name="Retry").click()

            expect(card.get_by_role("status")).to_have_text("Resolved: retry by eve-engineer")
            expect(page.locator("#case-status")).to_have_text("Completed", timeout=30_000)
            expect(page.locator('svg.net [data-place="p2"]')).to_have_attribute("data-tokens", "1")
            expect(page.locator("#timeline tbody tr").first).to_contain_text("Case completed")
            expect(page.locator("#timeline tbody")).to_contain_text("resolution: retry")
            screenshot(page, "supervisor-retried")
        executions, _ = simulation.executed_steps("c")
    assert executions == 1


def test_an_interruption_shows_while_an_operator_works_in_the_shared_area(
    page: Page, live_url: str, sign_in: SignIn, screenshot: Screenshot, tmp_path: Path
) -> None:
    with Simulation(shared_space(), tmp_path, time_scale=0.5) as simulation:
        engineer = factories.make_member(simulation.organisation, Role.ENGINEER, "eve-engineer")
        operator = simulation.users["o"]
        simulation.cobot("c").call("Simulator/InjectFault", "slow-steps", SLOWDOWN)
        with simulation.running(operators=False):
            [case_id] = simulation.start_cases(1)
            case = Case.objects.get(pk=case_id)
            load = until(lambda: case.work_items.filter(task="to1").first())
            services.start_work_item(load, user=operator)
            services.complete_work_item(load, user=operator)
            until(lambda: Job.objects.filter(case=case, state=JobState.RUNNING).exists())
            sign_in(page, engineer)
            page.goto(f"{live_url}/cases/{case_id}/")
            expect(page.locator("#interruptions")).to_contain_text("No interruptions.")

            inspect = until(lambda: case.work_items.filter(task="to2").first())
            services.start_work_item(inspect, user=operator)
            interruptions = page.locator("#interruptions")
            expect(interruptions).to_contain_text("(ongoing)", timeout=LIVE)
            simulation.cobot("c").call("Simulator/ClearFault")
            expect(interruptions).to_contain_text("inspect")
            expect(interruptions).to_contain_text("Pause")
            expect(page.locator('svg.net [data-task="to2"]')).to_have_attribute(
                "data-state", "running"
            )
            screenshot(page, "supervisor-interruption")

            services.complete_work_item(inspect, user=operator)
            expect(interruptions).not_to_contain_text("(ongoing)", timeout=LIVE)
            expect(interruptions.locator("td.duration")).to_have_text(re.compile(r"^\d+\.\d s$"))
            expect(page.locator("#case-status")).to_have_text("Completed", timeout=30_000)
            expect(page.locator("#timeline tbody")).to_contain_text("Task resumed")


def _unlocked(cobot: Any) -> bool:
    try:
        cobot.call("Simulator/UnlockProtectiveStop")
    except Exception:
        return False  # too soon after the stop: a UR controller waits too
    return True


def test_an_outsider_gets_404_and_an_operator_403(
    page: Page,
    live_url: str,
    outsider: User,
    operator: User,
    choice_case: Case,
    sign_in: SignIn,
    screenshot: Screenshot,
) -> None:
    sign_in(page, outsider)
    response = page.goto(f"{live_url}/cases/{choice_case.pk}/")
    assert response is not None
    assert response.status == 404
    expect(page.locator("body")).not_to_contain_text("count parts")
    screenshot(page, "supervisor-outsider-404")

    page.context.clear_cookies()
    sign_in(page, operator)
    response = page.goto(f"{live_url}/cases/{choice_case.pk}/")
    assert response is not None
    assert response.status == 403
    expect(page.get_by_role("alert")).to_have_text(
        "Only engineers and admins of the organisation supervise its cases."
    )
    screenshot(page, "supervisor-operator-403")
