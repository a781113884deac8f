"""A BPMN call activity that calls no process of its file is resolved against the importing
organisation's published patterns, by name; another organisation's patterns are never seen."""

from typing import Any

from django.contrib.auth.models import User
from rest_framework.test import APIClient

from hrc.engine.bpmn import BPMN_NAMESPACE
from hrc.organisations.models import Organisation
from hrc.patterns import services
from hrc.patterns.models import PatternModel
from tests import factories

# The prototype's Bonita processes called `SpotTape` from their main process.
CALLING_BPMN = f"""<?xml version="1.0" encoding="UTF-8"?>
<definitions xmlns="{BPMN_NAMESPACE}" id="defs" targetNamespace="urn:test" name="Cell 2 taping">
  <process id="Main" isExecutable="true">
    <laneSet id="ls">
      <lane id="anna" name="Operator Anna">
        <flowNodeRef>start</flowNodeRef><flowNodeRef>prepare</flowNodeRef>
        <flowNodeRef>tape</flowNodeRef><flowNodeRef>done</flowNodeRef>
      </lane>
    </laneSet>
    <startEvent id="start"/>
    <userTask id="prepare" name="prepare panel"/>
    <callActivity id="tape" name="tape the spots" calledElement="SpotTape"/>
    <endEvent id="done"/>
    <sequenceFlow id="f1" sourceRef="start" targetRef="prepare"/>
    <sequenceFlow id="f2" sourceRef="prepare" targetRef="tape"/>
    <sequenceFlow id="f3" sourceRef="tape" targetRef="done"/>
  </process>
</definitions>"""


def _import(client: APIClient, body: str) -> Any:
    return client.post("/api/patterns/import/", body.encode(), content_type="application/xml")


def _publish(organisation: Organisation, name: str, by: User) -> None:
    """Publishes a pattern whose tasks say whose they are: `<name>: prepare`, `<name>: place`."""
    document = factories.valid_document()
    labels = iter((f"{name}: prepare", f"{name}: place"))
    for transition in document["processes"][0]["transitions"]:
        transition["label"] = next(labels)
    pattern = factories.make_pattern(organisation, name=name, created_by=by, draft=document)
    services.publish_pattern(pattern, published_by=by)


def _labels(draft: dict[str, Any]) -> list[str]:
    return [
        transition.get("label") or ""
        for process in draft["processes"]
        for transition in process["transitions"]
    ]


def test_a_call_activity_naming_a_published_pattern_of_the_organisation_imports(
    engineer_client: APIClient, organisation: Organisation, engineer: User
) -> None:
    _publish(organisation, "spottape", engineer)

    response = _import(engineer_client, CALLING_BPMN)

    assert response.status_code == 201, response.data
    labels = _labels(response.data["draft"])
    assert any("tape the spots" in label for label in labels)
    assert {"spottape: prepare", "spottape: place"} <= set(labels)


def test_the_call_activity_may_name_the_pattern_by_its_own_name(
    engineer_client: APIClient, organisation: Organisation, engineer: User
) -> None:
    _publish(organisation, "Tape the spots", engineer)

    response = _import(engineer_client, CALLING_BPMN)

    assert response.status_code == 201, response.data
    assert "Tape the spots: place" in _labels(response.data["draft"])


def test_another_organisations_pattern_of_that_name_is_never_called(
    engineer_client: APIClient,
    organisation: Organisation,
    other_organisation: Organisation,
    outsider: User,
) -> None:
    _publish(other_organisation, "SpotTape", outsider)

    response = _import(engineer_client, CALLING_BPMN)

    assert response.status_code == 400
    assert response.data["detail"].startswith("The BPMN file cannot be imported: ")
    (issue,) = response.data["errors"]
    assert issue["elements"] == ["tape"]
    assert "tape the spots" in issue["message"]
    assert "SpotTape" in issue["message"]
    assert not PatternModel.objects.filter(organisation=organisation).exists()
