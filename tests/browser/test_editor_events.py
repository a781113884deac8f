"""Timers, cancellation and imported pieces to rewrite, in the pattern editor (issue 20).

An engineer gives a silent transition a timer and a list of what it cancels through the
properties panel, sees both marked on the canvas and finds them in the saved draft; an imported
model carries a condition to rewrite, which the check holds against it until the engineer says it
is rewritten.
"""

import json
import re
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
from django.contrib.auth.models import User
from playwright.sync_api import Locator, Page, expect

from hrc.organisations.models import Organisation
from hrc.patterns.models import PatternModel
from tests import factories
from tests.browser.drawing import (
    CHECKED,
    click_element,
    element_box,
    open_editor,
    pattern_badge,
    select_element,
)
from tests.support.polling import until

pytestmark = pytest.mark.django_db(transaction=True)

SignIn = Callable[[Page, User], None]
Screenshot = Callable[[Page, str], Path]
EXAMPLES = Path(__file__).resolve().parents[2] / "hrc" / "patterns" / "examples"
CANCELLED = re.compile(r"\bhrc-cancelled\b")
RUNNING = re.compile(r"\bhrc-running\b")
# A drilling step with an interrupting timeout, as a BPMN boundary timer imports: t1 arms the
# timeout (p3); tb fires after 5 minutes and cancels the drilling, running or not.
TIMEOUT: dict[str, Any] = {
    "format": "hrc-pattern/1",
    "name": "Drilling with a timeout",
    "actors": [{"id": "c", "type": "cobot", "program": "Drill"}],
    "processes": [
        {
            "id": "N",
            "workpiece": "plate",
            "actors": ["c"],
            "places": [{"id": f"p{n}", **({"tokens": 1} if n == 1 else {})} for n in range(1, 6)],
            "transitions": [
                {"id": "t1"},
                {"id": "tc1", "performer": "c", "label": "drill"},
                {"id": "t2"},
                {"id": "tb", "label": "timeout", "timer": "PT5M", "cancels": ["p2", "tc1", "p4"]},
            ],
            "arcs": [
                ["p1", "t1"],
                ["t1", "p2"],
                ["t1", "p3"],
                ["p2", "tc1"],
                ["tc1", "p4"],
                ["p4", "t2"],
                ["p3", "t2"],
                ["t2", "p5"],
                ["p3", "tb"],
                ["tb", "p5"],
            ],
        }
    ],
    "constraints": [],
}
REWRITE = "The condition ${amount > limit} is JUEL, which hrc does not read: write it as a guard."


def test_a_timer_and_what_a_transition_cancels_are_set_in_the_panel_drawn_and_saved(
    page: Page,
    live_url: str,
    engineer: User,
    organisation: Organisation,
    sign_in: SignIn,
    screenshot: Screenshot,
) -> None:
    pattern = _assembly(organisation)
    sign_in(page, engineer)
    open_editor(page, f"{live_url}/patterns/{pattern.pk}/edit/")
    panel = page.get_by_role("region", name="Properties")

    select_element(page, "t2")
    expect(panel.get_by_role("heading", name="Silent transition")).to_be_visible()
    _commit(panel, "Timer", "P1M")
    expect(panel.get_by_role("alert").filter(has_text="counts years or months")).to_be_visible()
    _commit(panel, "Timer", "pt5m")
    _commit(panel, "Cancels", "p3, nothing")
    expect(
        panel.get_by_role("alert").filter(
            has_text="Cannot cancel: nothing is no place or task of this pattern."
        )
    ).to_be_visible()
    _commit(panel, "Cancels", "p3, tc2")

    t2 = page.locator('.djs-element[data-element-id="t2"]')
    expect(t2.locator(".hrc-timer-mark")).to_have_count(1)
    expect(t2.locator(".hrc-timer-duration")).to_have_text("5 min")
    expect(t2.locator(".hrc-cancels-mark")).to_have_count(1)
    # Selected, t2 shows what it cancels; nothing else is marked.
    for cancelled in ("p3", "tc2"):
        expect(_element(page, cancelled)).to_have_class(CANCELLED)
    expect(page.locator(".djs-element.hrc-cancelled")).to_have_count(2)
    screenshot(page, "editor-timer-and-cancels")

    # Nothing selected, nothing is marked; the mouse over t2 marks them again.
    below = element_box(page, "o")
    page.mouse.click(below["x"] + 300, below["y"] + below["height"] + 60)
    expect(page.locator(".djs-element.hrc-cancelled")).to_have_count(0)
    page.locator('[data-element-id="t2"] .djs-hit').first.hover()
    expect(_element(page, "tc2")).to_have_class(CANCELLED)

    page.get_by_role("button", name="Save", exact=True).click()
    expect(page.locator(".hrc-toolbar .hrc-status")).to_have_text("Saved.", timeout=CHECKED)
    t2_saved = _transitions(pattern)["t2"]
    assert (t2_saved.get("timer"), t2_saved.get("cancels")) == ("PT5M", ["p3", "tc2"])


def test_a_condition_to_rewrite_holds_the_model_until_the_engineer_marks_it_rewritten(
    page: Page,
    live_url: str,
    engineer: User,
    organisation: Organisation,
    sign_in: SignIn,
    screenshot: Screenshot,
) -> None:
    document = json.loads((EXAMPLES / "synch_1o1c_assembly.json").read_text())
    document["processes"][0]["transitions"][0]["rewrite"] = REWRITE  # t1, the split
    pattern = factories.make_pattern(organisation, draft=document, name=document["name"])
    sign_in(page, engineer)
    open_editor(page, f"{live_url}/patterns/{pattern.pk}/edit/")
    panel = page.get_by_role("region", name="Properties")

    badge = page.locator('.hrc-issue-badge.hrc-error[data-element="t1"][data-codes~="to-rewrite"]')
    expect(badge).to_have_count(1, timeout=CHECKED)
    expect(page.locator('.hrc-issue[data-code="to-rewrite"]')).to_have_count(1)
    expect(_element(page, "t1")).to_have_class(re.compile(r"\bhrc-has-error\b"))

    select_element(page, "t1")
    note = panel.get_by_role("note", name="To rewrite")
    expect(note).to_contain_text(REWRITE)
    screenshot(page, "editor-condition-to-rewrite")
    # The engineer writes the guard, then says the note is dealt with.
    _commit(panel, "Guard", "data.amount > data.limit")
    note.get_by_role("button", name="Rewritten").click()
    expect(note).to_have_count(0)
    expect(page.locator('.hrc-issue[data-code="to-rewrite"]')).to_have_count(0, timeout=CHECKED)
    expect(badge).to_have_count(0)

    page.get_by_role("button", name="Save", exact=True).click()
    expect(page.locator(".hrc-toolbar .hrc-status")).to_have_text("Saved.", timeout=CHECKED)
    until(lambda: "rewrite" not in _transitions(pattern)["t1"])
    assert _transitions(pattern)["t1"]["guard"] == "data.amount > data.limit"


def test_the_token_game_cancels_a_running_task_and_a_step_back_resumes_it(
    page: Page,
    live_url: str,
    engineer: User,
    organisation: Organisation,
    sign_in: SignIn,
) -> None:
    pattern = factories.make_pattern(organisation, draft=TIMEOUT, name=TIMEOUT["name"])
    sign_in(page, engineer)
    open_editor(page, f"{live_url}/patterns/{pattern.pk}/edit/")
    expect(page.locator('[data-element-id="tb"] .hrc-timer-duration')).to_have_text("5 min")
    # Soundness holds only because tb cancels what it interrupts.
    expect(pattern_badge(page)).to_have_attribute("data-sound", "true", timeout=CHECKED)
    page.get_by_role("button", name="Token game").click()
    bar = page.get_by_role("toolbar", name="Token game")
    # Each click once the game shows what the last one did: on a loaded machine a click that
    # comes before the game is on, or before t1 has fired, fires nothing.
    expect(bar.locator(".hrc-game-caption")).to_contain_text("Can fire: t1")
    click_element(page, "t1")
    expect(page.locator('[data-element-id="p2"] .hrc-token')).to_have_count(1)
    click_element(page, "tc1")
    expect(_element(page, "tc1")).to_have_class(RUNNING)

    click_element(page, "tb")
    expect(bar.locator(".hrc-game-caption")).to_contain_text("Fired: “timeout”")
    expect(_element(page, "tc1")).not_to_have_class(RUNNING)
    expect(page.locator('[data-element-id="p5"] .hrc-token')).to_have_count(1)
    expect(page.locator(".djs-element .hrc-token")).to_have_count(1)

    bar.get_by_role("button", name="↶ Undo firing").click()
    expect(_element(page, "tc1")).to_have_class(RUNNING)
    expect(page.locator('[data-element-id="p3"] .hrc-token')).to_have_count(1)
    expect(page.locator('[data-element-id="p5"] .hrc-token')).to_have_count(0)


def _commit(panel: Locator, label: str, value: str) -> None:
    """Types `value` into the properties panel's field `label` and leaves it, which commits it."""
    field = panel.get_by_label(label, exact=True)
    field.fill(value)
    field.press("Tab")


def _element(page: Page, element_id: str) -> Locator:
    return page.locator(f'.djs-element[data-element-id="{element_id}"]')


def _assembly(organisation: Organisation) -> PatternModel:
    document = json.loads((EXAMPLES / "synch_1o1c_assembly.json").read_text())
    return factories.make_pattern(organisation, draft=document, name=document["name"])


def _transitions(pattern: PatternModel) -> dict[str, dict[str, Any]]:
    pattern.refresh_from_db()
    return {t["id"]: t for t in pattern.draft["processes"][0]["transitions"]}
