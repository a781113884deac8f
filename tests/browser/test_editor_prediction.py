"""The editor's Predict panel in a real browser (issue 22).

An engineer opens use case 2b, whose version 1 has one operator run every case and whose
draft has a second operator take every other case; predicts the draft two cases at once,
reads its cycle time and each lane's utilisation, finds the bottleneck the server named
marked on the canvas, then sets the draft beside version 1.
"""

import json
import re
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
from django.contrib.auth.models import User
from playwright.sync_api import Locator, Page, Response, expect

from hrc.organisations.models import Organisation
from hrc.patterns import services as pattern_services
from hrc.patterns.models import PatternModel
from tests import factories
from tests.browser.conftest import assert_fits
from tests.browser.drawing import CHECKED, open_editor, pattern_badge

pytestmark = pytest.mark.django_db(transaction=True)

SignIn = Callable[[Page, User], None]
Screenshot = Callable[[Page, str], Path]
USE_CASES = Path(__file__).resolve().parents[2] / "hrc" / "patterns" / "examples" / "use_cases"
BOTTLENECK = re.compile(r"\bhrc-bottleneck\b")
CRITICAL = re.compile(r"\bhrc-critical\b")
# A simulation of 1000 cases, twice for a comparison, on a loaded machine.
PREDICTED = 60_000
# Any Content-Security-Policy violation on the page, kept for the test to read.
LISTEN = """
window.hrcViolations = [];
document.addEventListener("securitypolicyviolation", (event) => {
  window.hrcViolations.push(`${event.violatedDirective} blocked ${event.blockedURI || "inline"}`);
});
"""


@pytest.fixture
def spot_taping(organisation: Organisation, engineer: User) -> PatternModel:
    """Use case 2b with version 1 published for one operator running every case, and a draft
    where a second operator runs every other case (its `simulation` variants)."""
    draft = json.loads((USE_CASES / "2b_extended_spot_taping_queue_variant.json").read_text())
    one_operator = {key: value for key, value in draft.items() if key != "simulation"}
    pattern = factories.make_pattern(organisation, draft=one_operator, name=draft["name"])
    pattern_services.publish_pattern(pattern, published_by=engineer)
    return pattern_services.update_pattern(pattern, draft=draft)


def _predicted(page: Page, button: Locator) -> dict[str, Any]:
    """Clicks the button and answers the prediction the server sent back."""
    with page.expect_response(
        lambda response: response.url.endswith("/api/patterns/predict/"), timeout=PREDICTED
    ) as answer:
        button.click()
    response: Response = answer.value
    assert response.status == 200, response.text()
    body: dict[str, Any] = response.json()
    return body


def _open_predict_panel(page: Page, url: str) -> Locator:
    """The draft at `url` in the editor, checked valid, with its Predict panel open."""
    open_editor(page, url)
    expect(pattern_badge(page)).to_have_attribute("data-valid", "true", timeout=CHECKED)
    page.get_by_role("toolbar", name="Pattern").get_by_role("button", name="Predict").click()
    return page.get_by_role("region", name="Prediction")


def _error_of(field: Locator) -> Locator:
    """The message the panel shows beside a field."""
    return field.locator("xpath=ancestor::div[contains(@class, 'hrc-field')][1]").locator(
        ".hrc-field-error"
    )


def _seconds(text: str) -> float:
    """A duration as the panel writes it ("45 s", "10 min 36 s", "2 h 03 min") in seconds."""
    parts: dict[str, float] = {
        unit: float(value) for value, unit in re.findall(r"([\d.]+) (h|min|s)", text)
    }
    return parts.get("h", 0) * 3600 + parts.get("min", 0) * 60 + parts.get("s", 0)


def test_an_engineer_predicts_the_draft_sees_the_bottleneck_and_compares_with_version_1(
    page: Page,
    live_url: str,
    engineer: User,
    spot_taping: PatternModel,
    sign_in: SignIn,
    screenshot: Screenshot,
) -> None:
    page.add_init_script(LISTEN)
    sign_in(page, engineer)
    open_editor(page, f"{live_url}/patterns/{spot_taping.pk}/edit/")
    expect(pattern_badge(page)).to_have_attribute("data-valid", "true", timeout=CHECKED)

    predict = page.get_by_role("toolbar", name="Pattern").get_by_role("button", name="Predict")
    expect(predict).to_have_attribute("aria-expanded", "false")
    predict.click()
    expect(predict).to_have_attribute("aria-expanded", "true")
    panel = page.get_by_role("region", name="Prediction")
    expect(panel).to_be_visible()
    # The draft's one operator lane, of one person unless told otherwise.
    expect(panel.get_by_label("o", exact=True)).to_have_value("1")
    panel.get_by_label("Cases at once").fill("2")

    answer = _predicted(page, panel.get_by_role("button", name="Predict", exact=True))
    prediction = answer["prediction"]
    assert answer["compared"] is None
    assert prediction["completed"] == prediction["cases"] == 1000
    figures = panel.locator(".hrc-predict-figures")
    for figure in ("p50", "p90", "p99"):
        expect(figures.locator(f'[data-figure="{figure}"]')).to_have_text(
            re.compile(r"^\d[\d.]* (s|min \d\d s|h \d\d min)$")
        )
    expect(figures.locator('[data-figure="throughput"]')).to_have_text(re.compile(r"/h$"))
    expect(panel.get_by_role("heading", name="Utilisation per lane")).to_be_visible()
    # Every lane that worked, with its share: the second operator stands in for o in half the cases.
    actors = {load["actor"]: load for load in prediction["actors"]}
    assert {"o", "o2", "cL", "cR"} <= set(actors)
    lanes = panel.locator(".hrc-predict-lanes > li")
    expect(lanes).to_have_count(len(actors))
    for actor, load in actors.items():
        lane = panel.locator(f'.hrc-predict-lanes > li[data-actor="{actor}"]')
        expect(lane.locator(".hrc-predict-share")).to_have_text(
            f"{round(load['utilisation'] * 100)} %"
        )
        expect(lane.get_by_role("meter")).to_have_attribute("value", re.compile(r"^(0(\.\d+)?|1)$"))

    # The task the server named as the bottleneck carries the marker; no other task does.
    bottleneck = prediction["bottleneck"]
    assert bottleneck is not None
    shape = page.locator(f'.djs-element[data-element-id="{bottleneck}"]')
    expect(shape).to_have_class(BOTTLENECK)
    expect(page.locator(".djs-element.hrc-bottleneck")).to_have_count(1)
    label = next(task["label"] for task in prediction["tasks"] if task["task"] == bottleneck)
    expect(panel.locator(".hrc-predict-bottleneck")).to_contain_text(label or bottleneck)
    path = {step["task"] for step in prediction["critical_path"]} - {bottleneck}
    for task in path:
        expect(page.locator(f'.djs-element[data-element-id="{task}"]')).to_have_class(CRITICAL)
    screenshot(page, "editor-prediction")

    panel.get_by_label("Published version").select_option(label="Version 1")
    compared = _predicted(page, panel.get_by_role("button", name="Compare"))
    assert compared["compared"]["version"]["number"] == 1
    version = compared["compared"]["prediction"]
    table = panel.get_by_role("table")
    expect(panel.get_by_role("heading", name="Draft vs version 1")).to_be_visible()
    expect(table.locator("thead th")).to_have_text(["", "Draft", "Version 1", "Difference"])
    rows = table.locator("tbody tr[data-row]")
    for key in ("p50", "p90", "throughput", "actor:o", "actor:cL", "actor:cR", "bottleneck"):
        cells = table.locator(f'tr[data-row="{key}"] td')
        expect(cells).to_have_count(3)
        expect(cells.nth(0)).not_to_have_text("–")
        expect(cells.nth(1)).not_to_have_text("–")
    # Version 1 has no second operator; its one operator takes every case.
    expect(table.locator('tr[data-row="actor:o2"] td').nth(1)).to_have_text("–")
    operator = {load["actor"]: load for load in version["actors"]}["o"]
    expect(table.locator('tr[data-row="actor:o"] td').nth(1)).to_have_text(
        f"{round(operator['utilisation'] * 100)} %"
    )
    assert operator["utilisation"] > actors["o"]["utilisation"]
    expect(rows).to_have_count(4 + len(set(actors) | {load["actor"] for load in version["actors"]}))
    assert_fits(page)
    # The comparison fits the side panel: nothing to scroll sideways for.
    side = page.locator(".hrc-side")
    assert side.evaluate("(side) => side.scrollWidth <= side.clientWidth")
    screenshot(page, "editor-prediction-compared")

    # A change to the model takes the marks off: they were for the model as it was.
    # Moved through the editor: a 15 px mouse drag at this zoom left the shape where it was.
    page.evaluate(
        """(id) => {
          const editor = window.hrcEditor;
          const shape = editor.get("elementRegistry").get(id);
          editor.get("modeling").moveElements([shape], {x: 0, y: 4});
        }""",
        bottleneck,
    )
    expect(shape).not_to_have_class(BOTTLENECK)
    expect(panel.locator(".hrc-predict-stale")).to_have_text(
        "The model changed since this prediction: predict again."
    )
    # Predicted again, the bottleneck is marked again; closing the panel takes the marks off.
    _predicted(page, panel.get_by_role("button", name="Predict", exact=True))
    expect(page.locator(".djs-element.hrc-bottleneck")).to_have_count(1)
    predict.click()
    expect(panel).to_be_hidden()
    expect(page.locator(".djs-element.hrc-bottleneck, .djs-element.hrc-critical")).to_have_count(0)
    assert page.evaluate("window.hrcViolations") == []


def test_a_refused_prediction_says_why_in_the_panel(
    page: Page,
    live_url: str,
    engineer: User,
    spot_taping: PatternModel,
    sign_in: SignIn,
) -> None:
    sign_in(page, engineer)
    panel = _open_predict_panel(page, f"{live_url}/patterns/{spot_taping.pk}/edit/")
    cases = panel.get_by_label("Cases", exact=True)
    status = panel.locator(".hrc-predict-status")
    # No number at all: the panel says so beside the field before posting anything.
    cases.fill("")
    panel.get_by_role("button", name="Predict", exact=True).click()
    expect(_error_of(cases)).to_have_text("Cases must be a whole number.")
    expect(status).to_have_text("Nothing was sent: correct the marked fields.")
    # A number out of range: the server's refusal, in its words.
    cases.fill("0")
    with page.expect_response(lambda r: r.url.endswith("/api/patterns/predict/")) as answer:
        panel.get_by_role("button", name="Predict", exact=True).click()
    assert answer.value.status == 400
    detail = answer.value.json()["detail"]
    assert detail
    expect(_error_of(cases)).to_be_empty()
    expect(status).to_have_attribute("role", "alert")
    expect(status).to_contain_text(f"The prediction failed: {detail}")
    expect(panel.locator(".hrc-predict-results")).to_be_empty()


def test_an_engineer_gives_a_task_its_time_and_the_prediction_takes_it(
    page: Page,
    live_url: str,
    engineer: User,
    spot_taping: PatternModel,
    sign_in: SignIn,
    screenshot: Screenshot,
) -> None:
    sign_in(page, engineer)
    panel = _open_predict_panel(page, f"{live_url}/patterns/{spot_taping.pk}/edit/")
    predict = panel.get_by_role("button", name="Predict", exact=True)
    p50 = panel.locator('.hrc-predict-figures [data-figure="p50"]')
    before = _predicted(page, predict)["prediction"]
    shown = p50.inner_text()
    first = "to_wires_L"
    assert before["bottleneck"] != first

    # The operator's first task, timed by nobody so far: 100 s every time.
    panel.locator(".hrc-predict-times > summary").click()
    task = panel.locator(f'fieldset[data-task="{first}"]')
    expect(task.locator("legend")).to_have_text("place the first wires on the left workpiece (o)")
    expect(task.locator(".hrc-predict-source")).to_contain_text("Assumed: ")
    task.get_by_label("Time").select_option(label="Fixed")
    task.get_by_label("Seconds").fill("100")
    with page.expect_request(lambda r: r.url.endswith("/api/patterns/predict/")) as sent:
        after = _predicted(page, predict)
    body = sent.value.post_data_json
    assert body is not None
    durations = body["options"]["durations"]
    assert durations == {first: {"kind": "fixed", "seconds": 100}}
    # Its time was the default's; now the case spends 100 s on it, and it holds the line up.
    mean = next(t["mean_duration"] for t in before["tasks"] if t["task"] == first)
    expect(p50).not_to_have_text(shown)
    grown = _seconds(p50.inner_text()) - _seconds(shown)
    assert abs(grown - (100 - mean)) < 10, (grown, mean)
    assert after["prediction"]["bottleneck"] == first
    expect(panel.locator(".hrc-predict-bottleneck")).to_have_attribute("data-task", first)
    expect(task.locator(".hrc-predict-source")).to_have_text("Given by you: fixed, 100 s")
    # Version 1 beside it is predicted with the same time for the task.
    panel.get_by_label("Published version").select_option(label="Version 1")
    compared = _predicted(page, panel.get_by_role("button", name="Compare"))["compared"]
    assert compared["durations"][first]["source"] == "given"
    expect(task.get_by_label("Seconds")).to_have_value("100")

    # A triangular time whose low is above its high: said beside it, and nothing goes out.
    other = panel.locator('fieldset[data-task="to_remove_R"]')
    other.get_by_label("Time").select_option(label="Triangular")
    other.get_by_label("Low (s)").fill("50")
    other.get_by_label("Mode (s)").fill("40")
    other.get_by_label("High (s)").fill("30")
    expect(_error_of(other.get_by_label("High (s)"))).to_have_text("High must not be below low.")
    posted: list[str] = []
    page.on("request", lambda r: posted.append(r.url) if "/predict/" in r.url else None)
    predict.click()
    expect(panel.locator(".hrc-predict-status")).to_have_text(
        "Nothing was sent: correct the marked fields."
    )
    assert posted == []
    # What was given stays for the next prediction.
    expect(task.get_by_label("Seconds")).to_have_value("100")
    expect(panel.get_by_text("Task times (2 given)")).to_be_visible()
    assert_fits(page)
    screenshot(page, "editor-prediction-times")
