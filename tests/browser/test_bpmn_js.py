"""hrc's BPMN exports open in bpmn-js, the viewer bpmn.io and Camunda's tools are built on.

The viewer is bpmn-js' own bundle from npm (a devDependency of frontend/), loaded
into a blank page; no server is involved. Each export must import without an
error or a warning, and every pool, lane, task, event, gateway and flow of it
must be drawn: bpmn-js draws only what the file's diagram (BPMNDI) places.
Opened in bpmn-js' modeler and saved again, an export still imports back into
hrc unchanged: the modeler keeps the marks that say what each element stands for.
"""

import xml.etree.ElementTree as ET
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
from playwright.sync_api import Page

from hrc.engine.bpmn import BPMN_NAMESPACE, BPMNDI_NAMESPACE, bpmn_to_pattern
from hrc.engine.bpmn_export import pattern_to_bpmn
from hrc.engine.document import read_pattern, write_pattern
from tests.engine.builders import example
from tests.engine.test_bpmn_export import configured

BUNDLES = Path(__file__).resolve().parents[2] / "frontend" / "node_modules" / "bpmn-js" / "dist"
VIEWER = BUNDLES / "bpmn-viewer.production.min.js"
MODELER = BUNDLES / "bpmn-modeler.production.min.js"
DRAWN = {
    "participant",
    "lane",
    "task",
    "userTask",
    "manualTask",
    "serviceTask",
    "scriptTask",
    "businessRuleTask",
    "sendTask",
    "receiveTask",
    "startEvent",
    "endEvent",
    "intermediateCatchEvent",
    "intermediateThrowEvent",
    "boundaryEvent",
    "parallelGateway",
    "exclusiveGateway",
    "eventBasedGateway",
    "sequenceFlow",
    "messageFlow",
    "association",
}

_IMPORT = """async (xml) => {
  const viewer = new BpmnJS({container: '#canvas'});
  try {
    const {warnings} = await viewer.importXML(xml);
    viewer.get('canvas').zoom('fit-viewport');
    const drawn = [...document.querySelectorAll('.djs-element')].map(
      (element) => element.getAttribute('data-element-id'));
    return {error: null, warnings: warnings.map((w) => w.message), drawn};
  } catch (error) {
    return {error: String(error), warnings: (error.warnings || []).map((w) => w.message), drawn: []};
  }
}"""


def _elements(text: str) -> set[str]:
    """The ids of the export's elements a viewer must draw."""
    prefix = f"{{{BPMN_NAMESPACE}}}"
    return {
        element.get("id", "")
        for element in ET.fromstring(text).iter()
        if isinstance(element.tag, str)
        and element.tag.startswith(prefix)
        and element.tag.removeprefix(prefix) in DRAWN
    }


def render(page: Page, text: str) -> dict[str, Any]:
    page.set_content('<div id="canvas" style="width: 1600px; height: 900px"></div>')
    page.add_script_tag(path=str(VIEWER))
    result: dict[str, Any] = page.evaluate(_IMPORT, text)
    return result


@pytest.mark.parametrize(
    ("name", "data"),
    [
        ("one-process-with-lanes", example("coop_2o2c_quality_inspection")),
        ("coexistence-pools", example("coex_2o1c_packaging_palletizing")),
        ("timers-and-messages", configured()),
    ],
)
def test_bpmn_js_draws_every_element_of_an_export(
    page: Page, screenshot: Callable[[Page, str], Path], name: str, data: dict[str, Any]
) -> None:
    text = pattern_to_bpmn(read_pattern(data))
    result = render(page, text)
    screenshot(page, f"bpmn-js-{name}")
    assert (result["error"], result["warnings"]) == (None, [])
    expected = _elements(text)
    assert len(expected) > 10
    assert expected - set(result["drawn"]) == set()


def test_bpmn_js_leaves_out_a_task_the_diagram_does_not_place(page: Page) -> None:
    """What the test above counts comes from the export's BPMNDI: a task without a shape is not drawn."""
    text = pattern_to_bpmn(read_pattern(example("coop_2o2c_quality_inspection")))
    root = ET.fromstring(text)
    plane = root.find(f"{{{BPMNDI_NAMESPACE}}}BPMNDiagram/{{{BPMNDI_NAMESPACE}}}BPMNPlane")
    assert plane is not None
    tasks = {task.get("id") for task in root.iter(f"{{{BPMN_NAMESPACE}}}task")}
    for shape in plane.findall(f"{{{BPMNDI_NAMESPACE}}}BPMNShape"):
        if shape.get("bpmnElement") in tasks:
            plane.remove(shape)
    result = render(page, ET.tostring(root, encoding="unicode"))
    assert tasks
    assert tasks & set(result["drawn"]) == set()


_SAVE = """async (xml) => {
  const modeler = new BpmnJS({container: '#canvas'});
  const {warnings} = await modeler.importXML(xml);
  const {xml: saved} = await modeler.saveXML({format: true});
  return {warnings: warnings.map((w) => w.message), saved};
}"""


@pytest.mark.parametrize(
    "data",
    [example("coex_2o1c_packaging_palletizing"), configured()],
    ids=["coexistence-pools", "timers-and-messages"],
)
def test_an_export_saved_by_the_bpmn_js_modeler_imports_back_unchanged(
    page: Page, data: dict[str, Any]
) -> None:
    pattern = read_pattern(data)
    text = pattern_to_bpmn(pattern)
    page.set_content('<div id="canvas" style="width: 1600px; height: 900px"></div>')
    page.add_script_tag(path=str(MODELER))
    result = page.evaluate(_SAVE, text)
    assert result["warnings"] == []
    assert result["saved"] != text  # written anew by bpmn-js, not handed back
    assert write_pattern(bpmn_to_pattern(result["saved"])) == write_pattern(pattern)
