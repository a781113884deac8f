"""The editor's import says what a refused file is, as the API words it: a BPMN or PNML file is
never called an hrc-pattern/1 document, and the elements it cannot take are named."""

import json
from collections.abc import Callable
from pathlib import Path

import pytest
from django.contrib.auth.models import User
from playwright.sync_api import FilePayload, Page, expect

from hrc.engine.bpmn import BPMN_NAMESPACE
from hrc.organisations.models import Organisation
from hrc.patterns.models import PatternModel
from tests import factories
from tests.browser.drawing import CHECKED, open_editor, pattern_badge

pytestmark = pytest.mark.django_db(transaction=True)

SignIn = Callable[[Page, User], None]
Screenshot = Callable[[Page, str], Path]
EXAMPLES = Path(__file__).resolve().parents[2] / "hrc" / "patterns" / "examples"

DANGLING_BPMN = f"""<?xml version="1.0" encoding="UTF-8"?>
<definitions xmlns="{BPMN_NAMESPACE}" id="defs" targetNamespace="urn:test">
  <process id="P">
    <startEvent id="start"/>
    <task id="pick" name="pick insert"/>
    <endEvent id="done"/>
    <sequenceFlow id="f1" sourceRef="start" targetRef="pick"/>
    <sequenceFlow id="to-nowhere" sourceRef="pick" targetRef="nowhere"/>
  </process>
</definitions>"""

# PIPE's dialect with an inhibitor arc, which hrc's nets cannot say.
PIPE_INHIBITOR = """<?xml version="1.0" encoding="iso-8859-1"?>
<pnml><net id="Net-One" type="P/T net"><token id="Default" enabled="true"/>
<place id="P0"><name><value>waiting room</value></name>
  <initialMarking><value>Default,1</value></initialMarking></place>
<transition id="T0"><name><value>treat</value></name></transition>
<arc id="P0 to T0" source="P0" target="T0"><type value="inhibitor"/>
  <inscription><value>Default,1</value></inscription></arc>
</net></pnml>"""


def _import(page: Page, name: str, text: str) -> None:
    payload = FilePayload(name=name, mimeType="application/octet-stream", buffer=text.encode())
    page.get_by_label("Import a file").set_input_files(files=[payload])


def test_a_refused_bpmn_or_pnml_file_is_named_as_what_it_is_and_changes_nothing(
    page: Page,
    live_url: str,
    engineer: User,
    organisation: Organisation,
    sign_in: SignIn,
    screenshot: Screenshot,
) -> None:
    document = json.loads((EXAMPLES / "synch_1o1c_assembly.json").read_text())
    pattern = factories.make_pattern(organisation, draft=document, name=document["name"])
    sign_in(page, engineer)
    open_editor(page, f"{live_url}/patterns/{pattern.pk}/edit/")
    expect(pattern_badge(page)).to_have_text("Synchronized", timeout=CHECKED)
    status = page.locator(".hrc-toolbar .hrc-status")

    _import(page, "cell4.bpmn", DANGLING_BPMN)
    expect(status).to_have_attribute("data-kind", "error")
    expect(status).to_contain_text("The BPMN file cannot be imported: ")
    expect(status).to_contain_text("to-nowhere")
    expect(status).not_to_contain_text("hrc-pattern")
    screenshot(page, "editor-import-refused-bpmn")

    _import(page, "triage.pnml", PIPE_INHIBITOR)
    expect(status).to_contain_text(
        "The PNML file cannot be imported: Arc P0 to T0 (“waiting room” -> “treat”) is a PIPE "
        "inhibitor arc"
    )
    expect(status).not_to_contain_text("hrc-pattern")

    assert page.url == f"{live_url}/patterns/{pattern.pk}/edit/"
    assert PatternModel.objects.count() == 1
