"""BPMN 2.0 and laid-out PNML through import and export: formats, detection, refusals that change nothing."""

import json
from pathlib import Path
from typing import Any

import pytest
from django.contrib.auth.models import User
from rest_framework.test import APIClient

from hrc.engine import read_pattern
from hrc.engine.bpmn import BPMN_NAMESPACE
from hrc.organisations.models import Organisation
from hrc.patterns import services
from hrc.patterns.models import PatternModel, PatternVersion
from tests import factories
from tests.hostile_xml import BILLION_LAUGHS, EXTERNAL_ENTITY

EXAMPLES = Path(__file__).resolve().parents[3] / "hrc" / "patterns" / "examples"

ASSEMBLY_BPMN = f"""<?xml version="1.0" encoding="UTF-8"?>
<definitions xmlns="{BPMN_NAMESPACE}" id="defs" targetNamespace="urn:test" name="Cell 4 assembly">
  <process id="P">
    <laneSet id="ls">
      <lane id="robot" name="UR5e robot"><flowNodeRef>pick</flowNodeRef></lane>
      <lane id="anna" name="Operator Anna"><flowNodeRef>prepare</flowNodeRef></lane>
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


def _import(client: APIClient, body: str | bytes, content_type: str, query: str = "") -> Any:
    data = body.encode() if isinstance(body, str) else body
    return client.post(f"/api/patterns/import/{query}", data, content_type=content_type)


# Import ---------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("content_type", "query"),
    [("application/xml", ""), ("text/xml", ""), ("application/octet-stream", "?format=bpmn")],
)
def test_a_bpmn_file_imports_as_a_laid_out_pattern(
    engineer_client: APIClient, organisation: Organisation, content_type: str, query: str
) -> None:
    response = _import(engineer_client, ASSEMBLY_BPMN, content_type, query)
    assert response.status_code == 201, response.data
    pattern = PatternModel.objects.get(pk=response.data["id"])
    assert (pattern.name, pattern.organisation) == ("Cell 4 assembly", organisation)
    draft = pattern.draft
    assert [(a["id"], a["type"]) for a in draft["actors"]] == [
        ("robot", "cobot"),
        ("anna", "operator"),
    ]
    performers = {t["id"]: t.get("performer") for t in draft["processes"][0]["transitions"]}
    assert (performers["pick"], performers["prepare"], performers["fork"]) == (
        "robot",
        "anna",
        None,
    )
    # Laid out on import: every node has a position, every actor a lane.
    assert [lane["actor"] for lane in draft["layout"]["lanes"]] == ["robot", "anna"]
    nodes = draft["processes"][0]["places"] + draft["processes"][0]["transitions"]
    assert all({"x", "y"} <= node["layout"].keys() for node in nodes)
    check = engineer_client.post(f"/api/patterns/{pattern.pk}/check/")
    assert check.data["sound"] is True


@pytest.mark.parametrize(
    ("body", "named"),
    [
        (
            ASSEMBLY_BPMN.replace('<parallelGateway id="join"/>', '<inclusiveGateway id="join"/>'),
            "join",
        ),
        (
            ASSEMBLY_BPMN.replace(
                '<task id="pick" name="pick insert"/>', '<subProcess id="pick"/>'
            ),
            "pick",
        ),
        (
            ASSEMBLY_BPMN.replace(
                '<startEvent id="start"/>',
                '<startEvent id="start"><timerEventDefinition/></startEvent>',
            ),
            "start",
        ),
        (ASSEMBLY_BPMN.replace('targetRef="done"', 'targetRef="nowhere"'), "f6"),
        (ASSEMBLY_BPMN.replace("</process>", ""), "line"),
    ],
    ids=["inclusive-gateway", "subprocess", "timer-event", "dangling-flow", "malformed"],
)
def test_a_bpmn_file_that_cannot_be_mapped_is_a_400_naming_the_element_and_creates_nothing(
    engineer_client: APIClient, body: str, named: str
) -> None:
    response = _import(engineer_client, body, "application/xml")
    assert response.status_code == 400
    assert named in response.data["detail"]
    if named != "line":
        assert any(named in issue["elements"] for issue in response.data["errors"])
    assert not PatternModel.objects.exists()


@pytest.mark.parametrize("query", ["", "?format=bpmn"])
@pytest.mark.parametrize(
    "xml", [BILLION_LAUGHS.encode(), EXTERNAL_ENTITY.encode()], ids=["bomb", "external"]
)
def test_hostile_xml_is_refused_whatever_the_format(
    engineer_client: APIClient, xml: bytes, query: str
) -> None:
    response = _import(engineer_client, xml, "application/xml", query)
    assert response.status_code == 400
    assert "DTD" in response.data["detail"]
    assert not PatternModel.objects.exists()


def test_xml_that_is_not_bpmn_still_imports_as_pnml(
    engineer_client: APIClient, pattern: PatternModel
) -> None:
    pnml = engineer_client.get(f"/api/patterns/{pattern.pk}/export/?format=pnml").content
    response = _import(engineer_client, pnml, "application/xml")
    assert response.status_code == 201, response.data
    assert read_pattern(response.data["draft"]) == read_pattern(pattern.draft)


def test_a_foreign_pnml_net_is_laid_out_on_import(engineer_client: APIClient) -> None:
    pnml = b"""<pnml><net id="n" type="http://www.pnml.org/version-2009/grammar/ptnet"><page id="pg">
      <place id="a"><initialMarking><text>1</text></initialMarking></place><transition id="t"/>
      <place id="b"/><arc id="a1" source="a" target="t"/><arc id="a2" source="t" target="b"/>
      </page></net></pnml>"""
    response = _import(engineer_client, pnml, "application/xml")
    assert response.status_code == 201, response.data
    draft = response.data["draft"]
    assert [lane["actor"] for lane in draft["layout"]["lanes"]] == [None]
    x = {
        n["id"]: n["layout"]["x"]
        for n in draft["processes"][0]["places"] + draft["processes"][0]["transitions"]
    }
    assert x["a"] < x["t"] < x["b"]


def test_a_json_import_is_kept_as_written(engineer_client: APIClient) -> None:
    response = engineer_client.post(
        "/api/patterns/import/",
        json.dumps(factories.valid_document()),
        content_type="application/json",
    )
    assert response.status_code == 201
    assert "layout" not in response.data["draft"]


def test_an_operator_may_not_import_bpmn(operator_client: APIClient) -> None:
    response = _import(operator_client, ASSEMBLY_BPMN, "application/xml")
    assert response.status_code == 403
    assert not PatternModel.objects.exists()


def test_an_outsider_cannot_import_bpmn_into_our_organisation(
    outsider_client: APIClient, organisation: Organisation
) -> None:
    response = _import(
        outsider_client, ASSEMBLY_BPMN, "application/xml", f"?organisation={organisation.pk}"
    )
    assert response.status_code == 400
    assert not organisation.patterns.exists()


# Export ---------------------------------------------------------------------------------------


@pytest.mark.parametrize("path", sorted(EXAMPLES.glob("*.json")), ids=lambda path: path.stem)
def test_every_example_exports_as_bpmn_and_comes_back_with_its_verdict(
    engineer_client: APIClient, organisation: Organisation, path: Path
) -> None:
    document = json.loads(path.read_text())
    pattern = factories.make_pattern(organisation, draft=document)
    exported = engineer_client.get(f"/api/patterns/{pattern.pk}/export/?format=bpmn")
    assert exported.status_code == 200
    assert exported["Content-Type"].startswith("application/xml")
    assert exported["Content-Disposition"].endswith('.bpmn"')
    assert b"BPMNDiagram" in exported.content
    imported = _import(engineer_client, exported.content, "application/xml")
    assert imported.status_code == 201, imported.data
    before = engineer_client.post(f"/api/patterns/{pattern.pk}/check/").data
    after = engineer_client.post(f"/api/patterns/{imported.data['id']}/check/").data
    assert (after["valid"], after["sound"], after["patterns"]) == (
        before["valid"],
        before["sound"],
        before["patterns"],
    )
    tasks = {t["id"]: t for t in document["processes"][0]["transitions"] if t.get("performer")}
    back = {t["id"]: t for p in imported.data["draft"]["processes"] for t in p["transitions"]}
    for task_id, task in tasks.items():
        assert (back[task_id]["performer"], back[task_id].get("label")) == (
            task["performer"],
            task.get("label"),
        )


def test_a_published_version_exports_as_bpmn(
    operator_client: APIClient, pattern: PatternModel, engineer: User
) -> None:
    version = services.publish_pattern(pattern, published_by=engineer)
    response = operator_client.get(f"/api/pattern-versions/{version.pk}/export/?format=bpmn")
    assert response.status_code == 200
    assert response["Content-Disposition"] == 'attachment; filename="hand-over-v1.bpmn"'
    assert b"<bpmn:definitions" in response.content
    assert PatternVersion.objects.count() == 1


def test_a_draft_bpmn_cannot_draw_is_a_400_naming_the_element(
    engineer_client: APIClient, organisation: Organisation
) -> None:
    pattern = factories.make_pattern(organisation, draft=factories.document_with_duplicate_ids())
    response = engineer_client.get(f"/api/patterns/{pattern.pk}/export/?format=bpmn")
    assert response.status_code == 400
    assert "cannot be exported as BPMN" in response.data["detail"]
    assert any("p2" in issue["elements"] for issue in response.data["errors"])


def test_an_outsider_cannot_export_our_pattern(
    outsider_client: APIClient, pattern: PatternModel
) -> None:
    response = outsider_client.get(f"/api/patterns/{pattern.pk}/export/?format=bpmn")
    assert response.status_code == 404
