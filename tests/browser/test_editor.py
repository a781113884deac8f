"""The pattern editor in a real browser (issue 6).

An engineer draws the thesis' Assembly pattern from an empty model with the
mouse and the keyboard, watches the server's check classify it, adds a time
constraint that contradicts the flow, sees the deadlock and replays its
witness, undoes it and publishes. The eight thesis examples open as the
thesis draws them and are saved as screenshots. Bad imports change nothing
and say what is wrong; outsiders and operators are kept out.
"""

import json
import re
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
from django.contrib.auth.models import User
from playwright.sync_api import FilePayload, Locator, Page, expect

from hrc.engine.taskconfig import DEVICE_CALLS
from hrc.organisations.models import Organisation
from hrc.patterns.models import PatternModel, PatternVersion
from tests import factories
from tests.browser.conftest import assert_fits
from tests.browser.drawing import (
    CHECKED,
    append_node,
    centre_of,
    click_element,
    connect,
    drop_tool,
    element_box,
    near,
    open_editor,
    pad_action,
    pattern_badge,
    select_element,
)
from tests.support.polling import until

pytestmark = pytest.mark.django_db(transaction=True)

SignIn = Callable[[Page, User], None]
Screenshot = Callable[[Page, str], Path]
EXAMPLES = Path(__file__).resolve().parents[2] / "hrc" / "patterns" / "examples"
RUNNING = re.compile(r"\bhrc-running\b")
STUCK = re.compile(r"\bhrc-stuck\b")


@pytest.mark.parametrize("example", sorted(path.stem for path in EXAMPLES.glob("*.json")))
def test_each_thesis_example_opens_in_its_lanes(
    page: Page,
    live_url: str,
    engineer: User,
    organisation: Organisation,
    sign_in: SignIn,
    screenshot: Screenshot,
    example: str,
) -> None:
    document = json.loads((EXAMPLES / f"{example}.json").read_text())
    pattern = factories.make_pattern(organisation, draft=document, name=document["name"])
    sign_in(page, engineer)
    open_editor(page, f"{live_url}/patterns/{pattern.pk}/edit/")

    declared = document["declared_pattern"].capitalize()
    expect(pattern_badge(page)).to_have_text(declared, timeout=CHECKED)
    expect(pattern_badge(page)).to_have_attribute("data-valid", "true")
    # Every actor is a lane; every task sits inside its actor's lane.
    for actor in document["actors"]:
        lane = page.locator(f'[data-element-id="{actor["id"]}"]')
        expect(lane).to_have_count(1)
        band = lane.bounding_box()
        assert band is not None
        for process in document["processes"]:
            for task in process["transitions"]:
                if task.get("performer") != actor["id"]:
                    continue
                box = page.locator(f'[data-element-id="{task["id"]}"]').bounding_box()
                assert box is not None
                middle = box["y"] + box["height"] / 2
                assert band["y"] <= middle <= band["y"] + band["height"], task["id"]
    expect(page.locator(".djs-connection .hrc-constraint")).to_have_count(
        len(document["constraints"])
    )
    screenshot(page, f"editor-{example}")


def test_an_engineer_draws_assembly_sees_it_checked_breaks_it_undoes_and_publishes(
    page: Page,
    live_url: str,
    engineer: User,
    organisation: Organisation,
    sign_in: SignIn,
    screenshot: Screenshot,
) -> None:
    sign_in(page, engineer)
    open_editor(page, f"{live_url}/patterns/new/")
    name = page.get_by_label("Pattern name")
    name.fill("Assembly (1 operator, 1 cobot)")
    name.press("Enter")

    page.get_by_role("button", name="Cobot lane").click()
    page.get_by_role("button", name="Operator lane").click()
    cobot, operator = element_box(page, "c"), element_box(page, "o")
    # A cobot task must name its program (a task-config error otherwise): the lane's default.
    page.mouse.click(cobot["x"] + 10, cobot["y"] + cobot["height"] / 2)  # the lane's name strip
    expect(page.locator('.djs-element.selected[data-element-id="c"]')).to_have_count(1)
    program = page.get_by_role("region", name="Properties").get_by_label("Default program")
    program.fill("Synchronized_SpotTaping")
    program.press("Tab")

    # The cobot's line: p1 (with the case's token), a split, pick, place and fix the insert.
    drop_tool(page, "Place", cobot["x"] + 100, cobot["y"] + cobot["height"] / 2)
    pad_action(page, "token.add")
    pad_action(page, "append.silent")
    append_node(page)
    for label in ("pick insert", "place insert", "fix insert"):
        append_node(page, label)
        append_node(page)
    # The operator's line, in the operator's lane under p2.
    p2_x, _ = centre_of(page, "p2")
    drop_tool(page, "Place", p2_x, operator["y"] + operator["height"] / 2)
    for label in ("prepare workpiece", "check assembled insert"):
        append_node(page, label)
        append_node(page)
    # The join and the end.
    select_element(page, "p5")
    pad_action(page, "append.silent")
    append_node(page)
    page.get_by_role("button", name="Show all").click()
    connect(page, "t1", "p6")
    connect(page, "p8", "t2")
    screenshot(page, "editor-drawing-assembly-net")
    # The synchronisation: the cobot places only a prepared workpiece; the operator checks a fixed insert.
    connect(page, "to1", "tc2", "constraint.time")
    connect(page, "tc3", "to2", "constraint.time")

    expect(pattern_badge(page)).to_have_text("Synchronized", timeout=CHECKED)
    expect(pattern_badge(page)).to_have_attribute("data-valid", "true")
    screenshot(page, "editor-drawn-assembly")

    # A time constraint against the flow: the cobot's placing before the operator's preparing.
    connect(page, "tc2", "to1", "constraint.time")
    expect(pattern_badge(page)).to_have_attribute("data-sound", "false", timeout=CHECKED)
    for task in ("tc2", "to1"):
        expect(page.locator(f'.hrc-issue-badge.hrc-error[data-element="{task}"]')).to_be_visible()
    deadlock = page.locator(".hrc-issue", has_text="can get stuck")
    # The firings in the drawing's words: tc1 is "pick insert".
    expect(deadlock.locator(".hrc-witness-steps li")).to_have_text(
        ["t1", "start “pick insert”", "complete “pick insert”"]
    )
    deadlock.get_by_role("button", name="Play the witness").click()
    bar = page.get_by_role("toolbar", name="Token game")
    for _ in range(3):
        bar.get_by_role("button", name="Fire next step ↷").click()
    expect(bar.locator(".hrc-game-caption")).to_contain_text("Witness replayed (3 of 3)")
    # Where the witness ends: tc1 has completed, tc2 and to1 wait for each other.
    expect(page.locator('.djs-element[data-element-id="tc1"]')).not_to_have_class(RUNNING)
    expect(page.locator('.djs-element[data-element-id="p3"] .hrc-token')).to_have_count(1)
    for task in ("tc2", "to1"):
        expect(page.locator(f'.djs-element[data-element-id="{task}"]')).to_have_class(STUCK)
    screenshot(page, "editor-assembly-deadlock-witness")
    bar.get_by_role("button", name="Stop").click()

    # Undo takes the contradiction back; the check agrees again.
    select_element(page, "p1")
    page.keyboard.press("Control+z")
    expect(pattern_badge(page)).to_have_attribute("data-valid", "true", timeout=CHECKED)
    expect(pattern_badge(page)).to_have_text("Synchronized")

    # wpassign is total: the new net works on "workpiece" until it is named; a net without one
    # is unassigned-workpiece, which the editor marks on the net's lanes.
    below = element_box(page, "o")
    page.mouse.click(below["x"] + 300, below["y"] + below["height"] + 60)  # nothing selected
    workpiece = page.get_by_role("region", name="Properties").get_by_label("Workpiece of net N")
    expect(workpiece).to_have_value("workpiece")
    workpiece.fill("")
    workpiece.press("Tab")
    unassigned = page.locator('.hrc-issue[data-code="unassigned-workpiece"]')
    expect(unassigned).to_contain_text("The drawing works on no workpiece", timeout=CHECKED)
    for lane in ("c", "o"):
        expect(page.locator(f'.djs-shape.hrc-has-error[data-element-id="{lane}"]')).to_have_count(1)
        badge = page.locator(f'.hrc-issue-badge.hrc-error[data-element="{lane}"]')
        expect(badge).to_have_attribute("data-codes", "unassigned-workpiece")
    screenshot(page, "editor-assembly-no-workpiece")
    workpiece = page.get_by_role("region", name="Properties").get_by_label("Workpiece of net N")
    workpiece.fill("w")
    workpiece.press("Tab")
    expect(pattern_badge(page)).to_have_attribute("data-valid", "true", timeout=CHECKED)
    expect(page.locator(".djs-shape.hrc-has-error")).to_have_count(0)

    page.get_by_role("button", name="Publish", exact=True).click()
    expect(page.locator(".hrc-toolbar .hrc-status")).to_have_text(
        "Published version 1.", timeout=CHECKED
    )
    version = PatternVersion.objects.get()
    assert version.number == 1
    # The message leads to the version's page, by the id the publish API returned.
    published = page.locator(".hrc-toolbar .hrc-status").get_by_role("link")
    expect(published).to_have_text("Published version 1.")
    expect(published).to_have_attribute("href", f"/patterns/versions/{version.pk}/")
    assert version.pattern.name == "Assembly (1 operator, 1 cobot)"
    _assert_is_the_thesis_assembly(version.document)
    screenshot(page, "editor-assembly-published")


def _assert_is_the_thesis_assembly(document: dict[str, Any]) -> None:
    """The drawn model is the thesis' CP_synch_1O1C: the same net, actors and constraints."""
    thesis = json.loads((EXAMPLES / "synch_1o1c_assembly.json").read_text())
    (process,) = document["processes"]
    (expected,) = thesis["processes"]
    assert {a["id"]: a["type"] for a in document["actors"]} == {"c": "cobot", "o": "operator"}
    assert {a["id"]: a.get("program") for a in document["actors"]} == {
        "c": "Synchronized_SpotTaping",
        "o": None,
    }
    assert sorted(process["actors"]) == ["c", "o"]
    assert process["workpiece"] == expected["workpiece"]
    assert sorted(p["id"] for p in process["places"]) == sorted(p["id"] for p in expected["places"])
    assert {p["id"]: p.get("tokens") for p in process["places"] if p.get("tokens")} == {"p1": 1}

    def tasks(net: dict[str, Any]) -> dict[str, tuple[str | None, str | None]]:
        return {t["id"]: (t.get("performer"), t.get("label")) for t in net["transitions"]}

    assert tasks(process) == tasks(expected)
    assert sorted(map(tuple, process["arcs"])) == sorted(map(tuple, expected["arcs"]))
    assert sorted((c["from"], c["to"], c["type"]) for c in document["constraints"]) == sorted(
        (c["from"], c["to"], c["type"]) for c in thesis["constraints"]
    )
    assert all("layout" in node for node in process["places"] + process["transitions"])


def test_a_second_constraint_type_on_one_pair_is_marked_on_its_tasks_and_lines(
    page: Page,
    live_url: str,
    engineer: User,
    organisation: Organisation,
    sign_in: SignIn,
    screenshot: Screenshot,
) -> None:
    document = json.loads((EXAMPLES / "synch_1o1c_assembly.json").read_text())
    document["constraints"].append({"from": "to1", "to": "tc2", "type": "space"})
    pattern = factories.make_pattern(organisation, draft=document, name="Conflicting")
    sign_in(page, engineer)
    open_editor(page, f"{live_url}/patterns/{pattern.pk}/edit/")

    conflict = page.locator('.hrc-issue[data-code="constraint-conflict"]')
    expect(conflict).to_contain_text(
        "“prepare workpiece” → “place insert” give one pair of tasks 2 types (time, space)",
        timeout=CHECKED,
    )
    expect(page.locator(".djs-connection.hrc-has-error .hrc-constraint")).to_have_count(2)
    for task in ("to1", "tc2"):
        badge = page.locator(f'.hrc-issue-badge.hrc-error[data-element="{task}"]')
        expect(badge).to_have_attribute("data-codes", re.compile(r"\bconstraint-conflict\b"))
    # The other constraint (tc3 → to2) is not part of it.
    expect(page.locator(".djs-connection .hrc-constraint")).to_have_count(3)
    screenshot(page, "editor-constraint-conflict")


def _commit(panel: Locator, label: str, value: str) -> None:
    """Types `value` into the properties panel's field `label` and leaves it, which commits it."""
    field = panel.get_by_label(label, exact=True)
    field.fill(value)
    field.press("Tab")


def _assembly(organisation: Organisation) -> PatternModel:
    document = json.loads((EXAMPLES / "synch_1o1c_assembly.json").read_text())
    return factories.make_pattern(organisation, draft=document, name=document["name"])


def _import(page: Page, name: str, text: str) -> None:
    payload = FilePayload(name=name, mimeType="application/octet-stream", buffer=text.encode())
    page.get_by_label("Import a file").set_input_files(files=[payload])


def _another_pattern(pattern: PatternModel) -> Callable[[str], bool]:
    """Matches the editor's address for any pattern but this one."""
    return lambda url: (
        bool(re.search(r"/patterns/\d+/edit/$", url))
        and not url.endswith(f"/patterns/{pattern.pk}/edit/")
    )


BROKEN_PNML = """<?xml version="1.0"?>
<pnml>
  <net id="N" type="http://www.pnml.org/version-2009/grammar/ptnet">
    <place id="p1">
  </net>
</pnml>"""

BPMN = """<?xml version="1.0" encoding="UTF-8"?>
<definitions xmlns="http://www.omg.org/spec/BPMN/20100524/MODEL" id="d" targetNamespace="urn:t" name="Cell 4">
  <process id="P">
    <laneSet id="ls">
      <lane id="robot" name="UR5e"><flowNodeRef>pick</flowNodeRef></lane>
      <lane id="anna" name="Anna"><flowNodeRef>prepare</flowNodeRef></lane>
    </laneSet>
    <startEvent id="start"/>
    <parallelGateway id="fork"/>
    <task id="pick" name="pick insert"/>
    <userTask id="prepare" name="prepare workpiece"/>
    <parallelGateway id="join"/>
    <endEvent id="done"/>
    <sequenceFlow id="f1" sourceRef="start" targetRef="fork"/>
    <sequenceFlow id="f2" sourceRef="fork" targetRef="pick"/>
    <sequenceFlow id="f3" sourceRef="pick" targetRef="join"/>
    <sequenceFlow id="f4" sourceRef="fork" targetRef="prepare"/>
    <sequenceFlow id="f5" sourceRef="prepare" targetRef="join"/>
    <sequenceFlow id="f6" sourceRef="join" targetRef="done"/>
  </process>
</definitions>"""


def test_a_malformed_file_changes_nothing_and_says_where(
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
    expect(pattern_badge(page)).to_have_text("Synchronized", timeout=CHECKED)
    nodes = page.locator(".djs-shape")
    count = nodes.count()
    status = page.locator(".hrc-toolbar .hrc-status")

    _import(page, "cell4.pnml", BROKEN_PNML)
    expect(status).to_have_attribute("role", "alert")
    expect(status).to_contain_text("cell4.pnml is not well-formed XML")
    expect(status).to_contain_text("line 5")
    expect(status).to_contain_text("inside <place>")
    screenshot(page, "editor-import-malformed-xml")

    broken = json.loads((EXAMPLES / "synch_1o1c_assembly.json").read_text())
    broken["processes"][0]["transitions"][3]["performer"] = ["c"]
    _import(page, "cell4.json", json.dumps(broken))
    expect(status).to_have_text(
        "processes[0] (N).transitions[3] (tc2).performer must be a string, got a list of 1."
    )
    _import(page, "cell4.json", '{"format": "hrc-pattern/1",\n "actors": [}')
    expect(status).to_have_text('The file is not JSON: unexpected "}" at line 2, column 13.')

    expect(nodes).to_have_count(count)
    assert page.url == f"{live_url}/patterns/{pattern.pk}/edit/"
    assert PatternModel.objects.count() == 1
    pattern.refresh_from_db()
    assert pattern.draft == json.loads((EXAMPLES / "synch_1o1c_assembly.json").read_text())


def test_a_bpmn_feature_hrc_does_not_map_is_refused_by_element_and_changes_nothing(
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
    status = page.locator(".hrc-toolbar .hrc-status")
    unmapped = BPMN.replace('<parallelGateway id="join"/>', '<inclusiveGateway id="join"/>')
    _import(page, "cell4.bpmn", unmapped)
    expect(status).to_have_attribute("data-kind", "error")
    expect(status).to_contain_text("join")
    expect(status).not_to_contain_text("Unsupported media type")
    screenshot(page, "editor-import-unmapped-bpmn")
    assert PatternModel.objects.count() == 1


def test_a_bpmn_file_imports_as_a_new_pattern_in_its_lanes(
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
    _import(page, "cell4.bpmn", BPMN)
    page.wait_for_url(_another_pattern(pattern), timeout=CHECKED)
    expect(page.locator("#hrc-editor")).to_have_attribute("data-ready", "true")
    for lane in ("robot", "anna"):
        expect(page.locator(f'.djs-shape[data-element-id="{lane}"]')).to_have_count(1)
    expect(page.locator(".djs-shape .hrc-task")).to_have_count(2)
    screenshot(page, "editor-imported-bpmn")


def test_a_pattern_file_imports_as_a_new_pattern_and_exports_as_bpmn_and_pnml(
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
    polishing = (EXAMPLES / "coop_1o1c_polishing.json").read_text()
    _import(page, "polishing.json", polishing)
    page.wait_for_url(_another_pattern(pattern), timeout=CHECKED)
    imported = PatternModel.objects.exclude(pk=pattern.pk).get()
    assert page.url.endswith(f"/patterns/{imported.pk}/edit/")
    expect(page.locator("#hrc-editor")).to_have_attribute("data-ready", "true")
    expect(pattern_badge(page)).to_have_text("Cooperation", timeout=CHECKED)
    screenshot(page, "editor-imported-json")

    for format, marker in (
        ("bpmn", "http://www.omg.org/spec/BPMN/20100524/MODEL"),
        ("pnml", "<pnml"),
    ):
        with page.expect_download() as download:
            page.get_by_label("Export").select_option(format)
        text = Path(download.value.path()).read_text()
        assert marker in text
        assert "polish" in text


def test_the_token_game_fires_by_click_steps_back_and_runs_to_the_end(
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
    page.get_by_role("button", name="Token game").click()
    bar = page.get_by_role("toolbar", name="Token game")
    caption = bar.locator(".hrc-game-caption")
    expect(caption).to_have_text("Can fire: t1.")

    def tokens(place: str) -> Any:
        return page.locator(f'.djs-element[data-element-id="{place}"] .hrc-token')

    expect(tokens("p1")).to_have_count(1)
    click_element(page, "tc1")  # not enabled yet: nothing happens
    expect(caption).to_have_text("Can fire: t1.")
    click_element(page, "t1")
    expect(tokens("p1")).to_have_count(0)
    expect(tokens("p2")).to_have_count(1)
    click_element(page, "tc1")
    expect(page.locator('.djs-element[data-element-id="tc1"]')).to_have_class(RUNNING)
    expect(caption).to_contain_text("Fired: start “pick insert”.")
    click_element(page, "tc1")
    expect(caption).to_contain_text("Fired: complete “pick insert”.")
    expect(tokens("p3")).to_have_count(1)

    # The constraint places, on demand: tc2 waits for to1's completion.
    bar.get_by_label("Constraint places").check()
    expect(page.locator(".hrc-constraint-place", has_text="to1 done, for tc2: 0")).to_be_visible()
    # A click on the held-back task says which constraint holds it and whose task it waits for.
    click_element(page, "tc2")
    expect(page.locator('.djs-element[data-element-id="tc2"]')).not_to_have_class(RUNNING)
    expect(caption).to_have_text(
        "“place insert” cannot start yet, held back by the time constraint "
        "“prepare workpiece” → “place insert”: it waits for o's “prepare workpiece” to complete."
    )
    expect(page.locator('.djs-element[data-element-id="to1"]')).to_have_class(
        re.compile("hrc-awaited")
    )
    screenshot(page, "editor-token-game")

    # Back and forward are undo and redo of firings.
    expect(bar.get_by_role("button", name="Redo firing ↷")).to_be_disabled()
    bar.get_by_role("button", name="↶ Undo firing").click()
    expect(page.locator('.djs-element[data-element-id="tc1"]')).to_have_class(RUNNING)
    bar.get_by_role("button", name="Redo firing ↷").click()
    expect(tokens("p3")).to_have_count(1)

    bar.get_by_role("button", name="Fire randomly").click()
    expect(caption).to_contain_text("Nothing can fire.", timeout=20_000)
    expect(tokens("p9")).to_have_count(1)
    # Nothing was edited by playing.
    bar.get_by_role("button", name="Stop").click()
    expect(page.get_by_role("button", name="Undo")).to_be_disabled()


def test_a_refused_edit_says_why_and_draws_nothing(
    page: Page, live_url: str, engineer: User, organisation: Organisation, sign_in: SignIn
) -> None:
    page.set_viewport_size({"width": 1280, "height": 800})
    pattern = _assembly(organisation)
    sign_in(page, engineer)
    open_editor(page, f"{live_url}/patterns/{pattern.pk}/edit/")
    arcs = page.locator(".djs-connection .hrc-arc")
    constraints = page.locator(".djs-connection .hrc-constraint")
    count = arcs.count()
    hint = page.locator(".hrc-refusal")

    connect(page, "p2", "p3")
    expect(hint).to_have_text(
        "An arc cannot join two places (p2 → p3): put a transition between them."
    )
    connect(page, "tc1", "tc3", "constraint.func")
    expect(hint).to_have_text(
        "tc1 and tc3 are both tasks of c: a constraint joins tasks of different actors."
    )
    expect(arcs).to_have_count(count)
    expect(constraints).to_have_count(2)
    expect(page.get_by_role("button", name="Undo")).to_be_disabled()
    # The refusal leaves the constraints legend readable.
    refusal, legend = hint.bounding_box(), page.locator(".hrc-legend").bounding_box()
    assert refusal is not None
    assert legend is not None
    assert refusal["x"] >= legend["x"] + legend["width"] or (
        refusal["y"] + refusal["height"] <= legend["y"]
    ), (refusal, legend)


def test_an_outsider_gets_404_for_our_pattern(
    page: Page, live_url: str, outsider: User, organisation: Organisation, sign_in: SignIn
) -> None:
    pattern = _assembly(organisation)
    sign_in(page, outsider)
    response = page.goto(f"{live_url}/patterns/{pattern.pk}/edit/")
    assert response is not None
    assert response.status == 404
    page.goto(f"{live_url}/patterns/")
    expect(page.get_by_text(pattern.name)).to_have_count(0)


def test_an_operator_may_read_the_list_but_not_edit(
    page: Page,
    live_url: str,
    operator: User,
    organisation: Organisation,
    sign_in: SignIn,
    screenshot: Screenshot,
) -> None:
    pattern = _assembly(organisation)
    sign_in(page, operator)
    page.goto(f"{live_url}/patterns/")
    expect(page.get_by_text(pattern.name)).to_be_visible()
    expect(page.get_by_role("link", name=f"Open {pattern.name}")).to_have_count(0)
    response = page.goto(f"{live_url}/patterns/{pattern.pk}/edit/")
    assert response is not None
    assert response.status == 403
    expect(page.get_by_role("alert")).to_contain_text("Only engineers and admins")
    expect(page.locator("#hrc-editor")).to_have_count(0)
    screenshot(page, "editor-operator-refused")


def test_a_dragged_node_is_laid_out_again_and_undo_brings_it_back(
    page: Page, live_url: str, engineer: User, organisation: Organisation, sign_in: SignIn
) -> None:
    pattern = _assembly(organisation)
    sign_in(page, engineer)
    open_editor(page, f"{live_url}/patterns/{pattern.pk}/edit/")
    laid_out = element_box(page, "p3")
    x, y = centre_of(page, "p3")
    page.mouse.move(x, y)
    page.mouse.down()
    page.mouse.move(x + 30, y + 25, steps=8)
    page.mouse.up()
    dragged = element_box(page, "p3")
    assert dragged["x"] > laid_out["x"] + 20
    assert dragged["y"] > laid_out["y"] + 15

    page.get_by_role("button", name="Layout").click()
    until(lambda: near(element_box(page, "p3"), laid_out))
    # One undo takes the whole layout back; a second one the drag.
    page.keyboard.press("Control+z")
    assert near(element_box(page, "p3"), dragged)
    page.keyboard.press("Control+z")
    assert near(element_box(page, "p3"), laid_out)
    page.keyboard.press("Control+y")
    assert near(element_box(page, "p3"), dragged)


def test_task_properties_are_edited_beside_the_canvas_and_saved_in_the_draft(
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

    select_element(page, "tc2")
    expect(panel.get_by_role("heading", name="Cobot task")).to_be_visible()
    _commit(panel, "Instructions", "Place the insert in the fixture.")
    panel.get_by_label("Program", exact=True).fill("Assembly")
    panel.get_by_label("Program", exact=True).press("Tab")
    _commit(panel, "Step number", "4")
    _commit(panel, "Workspace", "=data.station")
    _commit(panel, "Pose list", "0.1, 0.2, 0.05, 0, 3.14, 0\n=data.insert_pose")
    _commit(panel, "Step number", "-2")
    expect(
        panel.get_by_role("alert").filter(
            has_text="The step's number must be a whole number ≥ 0 or an expression starting with ="
        )
    ).to_be_visible()
    screenshot(page, "editor-properties-cobot-task")

    select_element(page, "tc3")
    panel.get_by_label("Runs").select_option("device")
    # The calls offered are the engine's (taskconfig.DEVICE_CALLS), passed by the page.
    expect(panel.get_by_label("Device call").locator("option")).to_have_count(len(DEVICE_CALLS))
    panel.get_by_label("Device call").select_option("display.show")
    _commit(panel, "Argument text", "=data.message")

    select_element(page, "to2")
    expect(panel.get_by_role("heading", name="Operator task")).to_be_visible()
    panel.get_by_role("button", name="Add a form field").click()
    _commit(panel, "Name", "insert_ok")
    _commit(panel, "Title", "Insert seated")
    panel.get_by_label("Type").select_option("boolean")
    panel.get_by_label("required").check()

    select_element(page, "p1")
    _commit(panel, "Label", "workpiece arrives")
    page.get_by_role("button", name="Save", exact=True).click()
    expect(page.locator(".hrc-toolbar .hrc-status")).to_have_text("Saved.", timeout=CHECKED)

    pattern.refresh_from_db()
    transitions = {t["id"]: t for t in pattern.draft["processes"][0]["transitions"]}
    assert transitions["tc2"]["task"] == {
        "instructions": "Place the insert in the fixture.",
        "step": {
            "number": 4,
            "workspace": "=data.station",
            "poses": [[0.1, 0.2, 0.05, 0, 3.14, 0], "=data.insert_pose"],
            "program": "Assembly",
        },
    }
    assert transitions["tc3"]["task"] == {
        "device": {"call": "display.show", "args": {"text": "=data.message"}}
    }
    assert transitions["to2"]["task"]["form"] == {
        "type": "object",
        "properties": {"insert_ok": {"type": "boolean", "title": "Insert seated"}},
        "required": ["insert_ok"],
    }
    places = {p["id"]: p for p in pattern.draft["processes"][0]["places"]}
    assert places["p1"]["label"] == "workpiece arrives"
    # What the editor does not know travels unchanged.
    assert pattern.draft["source"] == "thesis, section 4.3.1, CP_synch_1O1C"
    # The server checks the configuration as part of the model.
    expect(pattern_badge(page)).to_have_attribute("data-valid", "true", timeout=CHECKED)


def test_messages_a_transition_waits_for_and_a_task_sends_are_edited_as_json(
    page: Page,
    live_url: str,
    engineer: User,
    organisation: Organisation,
    sign_in: SignIn,
) -> None:
    pattern = _assembly(organisation)
    sign_in(page, engineer)
    open_editor(page, f"{live_url}/patterns/{pattern.pk}/edit/")
    panel = page.get_by_role("region", name="Properties")

    select_element(page, "t1")
    expect(panel.get_by_role("heading", name="Silent transition")).to_be_visible()
    _commit(panel, "Waits for a message", '{"name": "part-ready"')
    expect(panel.get_by_role("alert").filter(has_text="Not JSON")).to_be_visible()
    _commit(
        panel,
        "Waits for a message",
        '{"name": "part-ready", "correlation": {"order": "=data.order"}}',
    )
    select_element(page, "tc3")
    _commit(
        panel, "Sends a message when it completes", '{"name": "done", "payload": {"by": "cobot"}}'
    )
    page.get_by_role("button", name="Save").click()

    def saved() -> bool:
        pattern.refresh_from_db()
        transitions = {t["id"]: t for t in pattern.draft["processes"][0]["transitions"]}
        waits = transitions["t1"].get("message")
        sends = transitions["tc3"].get("send")
        return bool(
            waits == {"name": "part-ready", "correlation": {"order": "=data.order"}}
            and sends == {"name": "done", "payload": {"by": "cobot"}}
        )

    until(saved)


def test_keys_select_copy_paste_delete_and_undo(
    page: Page, live_url: str, engineer: User, organisation: Organisation, sign_in: SignIn
) -> None:
    pattern = _assembly(organisation)
    sign_in(page, engineer)
    open_editor(page, f"{live_url}/patterns/{pattern.pk}/edit/")
    shapes = page.locator(".djs-shape")
    count = shapes.count()

    lane = element_box(page, "o")
    page.mouse.click(lane["x"] + 10, lane["y"] + lane["height"] / 2)  # on the lane's header
    page.keyboard.press("Delete")
    expect(page.locator(".hrc-refusal")).to_have_text(
        "The lane of o still holds tasks to1, to2: delete them or move them to another lane first."
    )
    expect(shapes).to_have_count(count)

    select_element(page, "tc1")
    page.keyboard.press("Control+c")
    page.keyboard.press("Control+v")
    lane = element_box(page, "c")
    # Free space at the end of the cobot's lane: the copy stays the cobot's.
    x, y = lane["x"] + lane["width"] - 30, lane["y"] + lane["height"] / 2
    page.mouse.move(x, y, steps=6)
    page.mouse.down()
    page.mouse.up()
    expect(shapes).to_have_count(count + 1)
    expect(page.locator('.djs-shape[data-element-id="tc4"]')).to_contain_text("pick insert")

    page.keyboard.press("Delete")
    expect(shapes).to_have_count(count)
    page.keyboard.press("Control+z")
    expect(shapes).to_have_count(count + 1)
    page.keyboard.press("Control+z")
    expect(shapes).to_have_count(count)
    page.keyboard.press("Control+a")
    expect(page.locator(".djs-element.selected")).to_have_count(
        page.locator(".djs-shape, .djs-connection").count() - 2  # not the two lanes
    )


def test_a_lane_moves_up_with_its_tasks_and_one_undo_puts_it_back(
    page: Page, live_url: str, engineer: User, organisation: Organisation, sign_in: SignIn
) -> None:
    pattern = _assembly(organisation)  # lanes c (the cobot's) above o
    sign_in(page, engineer)
    open_editor(page, f"{live_url}/patterns/{pattern.pk}/edit/")
    panel = page.get_by_role("region", name="Properties")
    cobot, operator, operator_task = (
        element_box(page, "c"),
        element_box(page, "o"),
        element_box(page, "to1"),
    )
    assert cobot["y"] < operator["y"]

    page.mouse.click(operator["x"] + 10, operator["y"] + operator["height"] / 2)
    expect(panel.get_by_role("button", name="Move lane down")).to_be_disabled()
    panel.get_by_role("button", name="Move lane up").click()
    until(lambda: abs(element_box(page, "o")["y"] - cobot["y"]) < 2)
    assert abs(element_box(page, "c")["y"] - operator["y"]) < 2  # both lanes are as tall
    # The operator's task went up with its lane, and is still the operator's.
    assert (
        abs(element_box(page, "to1")["y"] - (operator_task["y"] - (operator["y"] - cobot["y"]))) < 2
    )
    expect(panel.get_by_role("button", name="Move lane up")).to_be_disabled()
    page.get_by_role("button", name="Save", exact=True).click()
    expect(page.locator(".hrc-toolbar .hrc-status")).to_have_text("Saved.", timeout=CHECKED)
    pattern.refresh_from_db()
    lanes = {lane["actor"]: lane["y"] for lane in pattern.draft["layout"]["lanes"]}
    assert lanes["o"] < lanes["c"]
    performers = {t["id"]: t.get("performer") for t in pattern.draft["processes"][0]["transitions"]}
    assert performers == {
        "t1": None, "t2": None, "tc1": "c", "tc2": "c", "tc3": "c", "to1": "o", "to2": "o"
    }  # fmt: skip

    page.keyboard.press("Control+z")  # the whole swap, lanes and tasks
    until(lambda: near(element_box(page, "o"), operator))
    assert near(element_box(page, "c"), cobot)
    assert near(element_box(page, "to1"), operator_task)


def test_a_constraint_shows_its_task_names_and_reverses_with_undo(
    page: Page,
    live_url: str,
    engineer: User,
    organisation: Organisation,
    sign_in: SignIn,
    screenshot: Screenshot,
) -> None:
    page.set_viewport_size({"width": 1280, "height": 800})
    pattern = _assembly(organisation)
    sign_in(page, engineer)
    open_editor(page, f"{live_url}/patterns/{pattern.pk}/edit/")
    expect(pattern_badge(page)).to_have_attribute("data-valid", "true", timeout=CHECKED)
    # The first constraint of the example: to1 → tc2, drawn as a straight line between them.
    (x1, y1), (x2, y2) = centre_of(page, "to1"), centre_of(page, "tc2")
    page.mouse.click(x1 + (x2 - x1) / 2, y1 + (y2 - y1) / 2)
    panel = page.get_by_role("region", name="Properties")
    ends = panel.locator(".hrc-constraint-ends")
    expect(ends).to_have_text("“prepare workpiece” → “place insert” (time)")
    assert "to1" not in (ends.text_content() or "")
    screenshot(page, "editor-constraint-panel-1280")
    assert_fits(page)

    panel.get_by_role("button", name="Reverse").click()
    expect(ends).to_have_text("“place insert” → “prepare workpiece” (time)")
    _save_and_expect_constraints(page, pattern, {("tc2", "to1"), ("tc3", "to2")})

    page.get_by_role("button", name="Undo").click()
    expect(ends).to_have_text("“prepare workpiece” → “place insert” (time)")
    _save_and_expect_constraints(page, pattern, {("to1", "tc2"), ("tc3", "to2")})


def test_a_space_constraint_offers_the_modes_of_its_pair_of_actors(
    page: Page,
    live_url: str,
    engineer: User,
    organisation: Organisation,
    sign_in: SignIn,
) -> None:
    page.set_viewport_size({"width": 1280, "height": 800})
    document = json.loads((EXAMPLES / "coop_2o2c_quality_inspection.json").read_text())
    pattern = factories.make_pattern(organisation, draft=document, name=document["name"])
    sign_in(page, engineer)
    open_editor(page, f"{live_url}/patterns/{pattern.pk}/edit/")
    expect(pattern_badge(page)).to_have_attribute("data-valid", "true", timeout=CHECKED)
    panel = page.get_by_role("region", name="Properties")

    def select_constraint(first: str, second: str) -> None:
        (x1, y1), (x2, y2) = centre_of(page, first), centre_of(page, second)
        page.mouse.click(x1 + (x2 - x1) / 2, y1 + (y2 - y1) / 2)
        expect(panel.locator(".hrc-constraint-ends")).to_contain_text("(space)")

    # Two operators: one way only, the second waits; nothing to choose but that.
    select_constraint("to12", "to21")
    operators = panel.get_by_label("When both operators need the shared area")
    expect(operators.locator("option")).to_have_text(
        ["the second waits (the tablet tells them why)"]
    )
    # A cobot and an operator: the cobot pauses (the default) or slows down.
    select_constraint("tc12", "to11")
    mixed = panel.get_by_label("While the operator is in the shared area, the cobot")
    expect(mixed.locator("option")).to_have_text(["pauses", "slows down"])
    mixed.select_option(label="slows down")
    page.get_by_role("button", name="Save").click()

    def saved() -> bool:
        pattern.refresh_from_db()
        modes = {(c["from"], c["to"]): c.get("interrupt") for c in pattern.draft["constraints"]}
        return modes == {("tc12", "to11"): "slow", ("to12", "to21"): None, ("to22", "tc21"): None}

    until(saved)


def _save_and_expect_constraints(
    page: Page, pattern: PatternModel, expected: set[tuple[str, str]]
) -> None:
    page.get_by_role("button", name="Save").click()

    def saved() -> bool:
        pattern.refresh_from_db()
        return {(c["from"], c["to"]) for c in pattern.draft["constraints"]} == expected

    until(saved)


def test_lanes_come_by_dragging_and_appended_branches_stay_in_their_lane(
    page: Page, live_url: str, engineer: User, sign_in: SignIn
) -> None:
    sign_in(page, engineer)
    open_editor(page, f"{live_url}/patterns/new/")
    canvas = page.locator(".hrc-canvas").bounding_box()
    assert canvas is not None
    # Dragged from the palette and let go over the canvas, a lane tool adds its lane.
    for tool in ("Cobot lane", "Operator lane"):
        entry = page.get_by_role("button", name=tool, exact=True).bounding_box()
        assert entry is not None
        page.mouse.move(entry["x"] + entry["width"] / 2, entry["y"] + entry["height"] / 2)
        page.mouse.down()
        page.mouse.move(canvas["x"] + canvas["width"] / 2, canvas["y"] + 150, steps=10)
        page.mouse.up()
    expect(page.locator('.djs-element[data-element-id="c"]')).to_have_count(1)
    expect(page.locator('.djs-element[data-element-id="o"]')).to_have_count(1)

    # Three branches after one place in the cobot's lane: all three stay inside it.
    cobot = element_box(page, "c")
    drop_tool(page, "Place", cobot["x"] + 100, cobot["y"] + 30)
    first = page.get_by_role("region", name="Properties").get_by_label("Id").input_value()
    for _ in range(3):
        select_element(page, first)
        append_node(page)
        page.keyboard.press("Escape")
    lane = element_box(page, "c")
    tasks = page.locator('.djs-element[data-element-id^="tc"] .djs-hit')
    expect(tasks).to_have_count(3)
    for n in range(3):
        box = tasks.nth(n).bounding_box()
        assert box is not None
        assert lane["y"] <= box["y"]
        assert box["y"] + box["height"] <= lane["y"] + lane["height"]
