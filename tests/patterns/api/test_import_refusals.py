"""A refused import says what the file is: a BPMN or PNML file is never called an hrc-pattern/1
document, and its issues name the elements; nothing is created."""

from typing import Any

import pytest
from rest_framework.test import APIClient

from hrc.engine.bpmn import BPMN_NAMESPACE
from hrc.patterns.models import PatternModel
from tests.hostile_xml import BILLION_LAUGHS

# A flow into a node the process does not have: refused by any BPMN mapping.
DANGLING_BPMN = f"""<?xml version="1.0" encoding="UTF-8"?>
<definitions xmlns="{BPMN_NAMESPACE}" id="defs" targetNamespace="urn:test">
  <process id="P">
    <startEvent id="start"/>
    <task id="pick" name="pick insert"/>
    <endEvent id="done"/>
    <sequenceFlow id="f1" sourceRef="start" targetRef="pick"/>
    <sequenceFlow id="f2" sourceRef="pick" targetRef="nowhere"/>
  </process>
</definitions>"""

WEIGHTED_PNML = """<?xml version="1.0"?>
<pnml xmlns="http://www.pnml.org/version-2009/grammar/pnml">
  <net id="N" type="http://www.pnml.org/version-2009/grammar/ptnet">
    <place id="p1"><name><text>ready</text></name></place>
    <transition id="t1"><name><text>pick</text></name></transition>
    <place id="p2"/>
    <arc id="a1" source="p1" target="t1"/>
    <arc id="a2" source="t1" target="p2"><inscription><text>3</text></inscription></arc>
  </net>
</pnml>"""


def _import(client: APIClient, body: str, query: str = "") -> Any:
    return client.post(
        f"/api/patterns/import/{query}", body.encode(), content_type="application/xml"
    )


@pytest.mark.parametrize(
    ("body", "query", "kind", "named"),
    [
        (DANGLING_BPMN, "", "BPMN", "f2"),
        (DANGLING_BPMN.replace("</process>", ""), "", "BPMN", None),
        (WEIGHTED_PNML, "", "PNML", "a2"),
        (WEIGHTED_PNML.replace("</net>", ""), "", "PNML", None),
        (BILLION_LAUGHS, "?format=bpmn", "BPMN", None),
        (BILLION_LAUGHS, "", "PNML", None),
    ],
    ids=[
        "bpmn-unmapped",
        "bpmn-malformed",
        "pnml-weighted",
        "pnml-malformed",
        "bpmn-dtd",
        "pnml-dtd",
    ],
)
def test_a_refused_file_is_named_as_bpmn_or_pnml_never_as_an_hrc_pattern_document(
    engineer_client: APIClient, body: str, query: str, kind: str, named: str | None
) -> None:
    response = _import(engineer_client, body, query)

    assert response.status_code == 400
    detail = response.data["detail"]
    assert detail.startswith(f"The {kind} file cannot be imported: ")
    assert "hrc-pattern" not in detail
    assert response.data["code"] == "file-refused"
    assert response.data["errors"]
    assert all("hrc-pattern" not in issue["message"] for issue in response.data["errors"])
    if named:
        assert any(named in issue["elements"] for issue in response.data["errors"])
    assert not PatternModel.objects.exists()


def test_a_json_body_that_is_no_pattern_is_still_called_a_document(
    engineer_client: APIClient,
) -> None:
    response = engineer_client.post(
        "/api/patterns/import/",
        b'{"format": "hrc-pattern/1", "processes": {}}',
        content_type="application/json",
    )

    assert response.status_code == 400
    assert response.data["detail"].startswith("The document is not a readable hrc-pattern/1")


PIPE_NET = """<?xml version="1.0" encoding="iso-8859-1"?>
<pnml><net id="Net-One" type="P/T net"><token id="Default" enabled="true"/>
<place id="P0"><name><value>waiting room</value></name>
  <initialMarking><value>Default,1</value></initialMarking></place>
<place id="P1"><name><value>treated</value></name><initialMarking><value>0</value></initialMarking></place>
<transition id="T0"><name><value>treat</value></name><timed><value>true</value></timed></transition>
<arc id="P0 to T0" source="P0" target="T0"><type value="normal"/>
  <inscription><value>Default,1</value></inscription></arc>
<arc id="T0 to P1" source="T0" target="P1"><type value="inhibitor"/>
  <inscription><value>Default,1</value></inscription></arc>
</net></pnml>"""


def test_a_pipe_net_imports_and_what_it_cannot_say_is_refused_by_element(
    engineer_client: APIClient,
) -> None:
    refused = _import(engineer_client, PIPE_NET)
    assert refused.status_code == 400
    assert refused.data["detail"] == (
        "The PNML file cannot be imported: Arc T0 to P1 (“treat” -> “treated”) is a PIPE "
        "inhibitor arc; hrc nets have only normal arcs, each moving one token (an inhibitor arc "
        "tests a place for emptiness, which hrc's nets cannot say)."
    )

    imported = _import(engineer_client, PIPE_NET.replace('"inhibitor"', '"normal"'))
    assert imported.status_code == 201, imported.data
    places = imported.data["draft"]["processes"][0]["places"]
    assert [(p["id"], p.get("name"), p.get("tokens")) for p in places] == [
        ("P0", "waiting room", 1),
        ("P1", "treated", 0),
    ]
