"""The editor's helpers: check an unsaved document, lay it out, get its execution net."""

import json
from pathlib import Path
from typing import Any

import pytest
from rest_framework.test import APIClient

from hrc.engine import check_document
from hrc.patterns.models import PatternModel
from tests import factories

EXAMPLES = Path(__file__).resolve().parents[3] / "hrc" / "patterns" / "examples"
HELPERS = ["check-document", "layout", "execution-net"]


def _post(client: APIClient, helper: str, body: Any) -> Any:
    return client.post(
        f"/api/patterns/{helper}/", json.dumps(body), content_type="application/json"
    )


# Who may --------------------------------------------------------------------------------------


@pytest.mark.parametrize("helper", HELPERS)
def test_engineers_and_admins_may_use_the_helpers(
    engineer_client: APIClient, admin_client: APIClient, helper: str
) -> None:
    for client in (engineer_client, admin_client):
        response = _post(client, helper, factories.valid_document())
        assert response.status_code == 200, response.data


@pytest.mark.parametrize("helper", HELPERS)
def test_operators_users_without_membership_and_strangers_may_not(
    operator_client: APIClient,
    loner_client: APIClient,
    anonymous_client: APIClient,
    helper: str,
) -> None:
    for client in (operator_client, loner_client):
        response = _post(client, helper, factories.valid_document())
        assert response.status_code == 403
        assert "engineers and admins" in response.data["detail"]
    assert _post(anonymous_client, helper, factories.valid_document()).status_code in (401, 403)


@pytest.mark.parametrize("helper", HELPERS)
def test_an_engineer_of_another_organisation_learns_nothing_about_ours(
    outsider_client: APIClient, pattern: PatternModel, helper: str
) -> None:
    # The helpers read only the body: an outsider gets the answer for their own document,
    # and no id or name of ours appears in it.
    document = factories.valid_document()
    document["name"] = "Outsider's model"
    response = _post(outsider_client, helper, document)
    assert response.status_code == 200
    assert "Hand-over" not in json.dumps(response.data)
    assert str(pattern.pk) not in {str(v) for v in response.data.values() if isinstance(v, int)}


@pytest.mark.parametrize("helper", HELPERS)
def test_the_helpers_store_nothing(engineer_client: APIClient, helper: str) -> None:
    _post(engineer_client, helper, factories.valid_document())
    assert not PatternModel.objects.exists()


# check-document ------------------------------------------------------------------------------


@pytest.mark.parametrize("path", sorted(EXAMPLES.glob("*.json")), ids=lambda path: path.stem)
def test_check_document_answers_what_the_saved_check_answers(
    engineer_client: APIClient, organisation: Any, path: Path
) -> None:
    document = json.loads(path.read_text())
    unsaved = _post(engineer_client, "check-document", document)
    pattern = factories.make_pattern(organisation, draft=document)
    saved = engineer_client.post(f"/api/patterns/{pattern.pk}/check/")
    assert unsaved.status_code == 200
    assert unsaved.data == saved.data
    assert unsaved.data["valid"] is True


def test_check_document_reports_broken_rules_and_the_deadlock_witness(
    engineer_client: APIClient,
) -> None:
    unsound = _post(engineer_client, "check-document", factories.unsound_document())
    assert unsound.status_code == 200
    assert unsound.data == check_document(factories.unsound_document()).as_dict()
    assert unsound.data["sound"] is False
    assert unsound.data["errors"][0]["code"] == "unsound"
    assert "witness" in unsound.data["errors"][0]  # the firing sequence, empty at the start
    colliding = _post(engineer_client, "check-document", factories.document_with_duplicate_ids())
    assert colliding.status_code == 200
    assert "duplicate-id" in {e["code"] for e in colliding.data["errors"]}


@pytest.mark.parametrize("helper", HELPERS)
@pytest.mark.parametrize(
    ("body", "words"),
    [
        ({"format": "hrc-pattern/2", "processes": []}, "format"),
        ({"format": "hrc-pattern/1", "processes": "N"}, "processes must be a list"),
        ([1, 2], "must be a JSON object"),
    ],
)
def test_a_body_that_is_no_pattern_is_a_400_naming_the_problem(
    engineer_client: APIClient, helper: str, body: Any, words: str
) -> None:
    response = _post(engineer_client, helper, body)
    assert response.status_code == 400
    assert words in response.data["detail"]
    assert all(issue["code"] == "format" for issue in response.data["errors"])


@pytest.mark.parametrize("helper", HELPERS)
def test_a_body_that_is_not_json_is_a_400(engineer_client: APIClient, helper: str) -> None:
    response = engineer_client.post(
        f"/api/patterns/{helper}/", b'{"format": ', content_type="application/json"
    )
    assert response.status_code == 400
    assert response.data["detail"].startswith("JSON parse error")


# layout --------------------------------------------------------------------------------------


def test_layout_places_every_node_in_its_actors_lane(engineer_client: APIClient) -> None:
    document = json.loads((EXAMPLES / "synch_1o1c_assembly.json").read_text())
    response = _post(engineer_client, "layout", document)
    assert response.status_code == 200
    laid_out = response.data
    bands = {lane["actor"]: lane for lane in laid_out["layout"]["lanes"]}
    assert list(bands) == ["c", "o"]
    for transition in laid_out["processes"][0]["transitions"]:
        y = transition["layout"]["y"]
        if transition.get("performer"):
            lane = bands[transition["performer"]]
            assert lane["y"] < y < lane["y"] + lane["height"]
    # Nothing but the layout is new.
    for place in laid_out["processes"][0]["places"]:
        del place["layout"]
    for transition in laid_out["processes"][0]["transitions"]:
        del transition["layout"]
    del laid_out["layout"]
    assert laid_out == document


# execution-net -------------------------------------------------------------------------------


def test_execution_net_splits_tasks_and_compiles_constraints(engineer_client: APIClient) -> None:
    response = _post(engineer_client, "execution-net", factories.valid_document())
    assert response.status_code == 200
    net = response.data
    kinds = {p["id"]: p["kind"] for p in net["places"]}
    assert kinds == {
        "p1": "flow",
        "p2": "flow",
        "p3": "flow",
        "running:to1": "busy",
        "running:tc1": "busy",
        "time:to1>tc1": "constraint",
    }
    assert [t["id"] for t in net["transitions"]] == [
        "start:to1",
        "complete:to1",
        "start:tc1",
        "complete:tc1",
    ]
    assert ["time:to1>tc1", "start:tc1"] in net["arcs"]
    assert net["initial"] == {"p1": 1}


def test_execution_net_of_a_structurally_broken_model_is_a_400_with_the_issues(
    engineer_client: APIClient,
) -> None:
    document = factories.valid_document()
    document["processes"][0]["arcs"].append(["p3", "ghost"])
    response = _post(engineer_client, "execution-net", document)
    assert response.status_code == 400
    assert "structural rules" in response.data["detail"]
    assert "ghost" in response.data["detail"]
    assert "unknown-node" in {e["code"] for e in response.data["errors"]}


def test_an_unsound_model_still_has_an_execution_net_to_play(engineer_client: APIClient) -> None:
    response = _post(engineer_client, "execution-net", factories.unsound_document())
    assert response.status_code == 200
    assert ["time:tc1>to1", "start:to1"] in response.data["arcs"]


def test_the_helpers_are_in_the_openapi_schema(engineer_client: APIClient) -> None:
    schema = engineer_client.get("/api/schema/", HTTP_ACCEPT="application/vnd.oai.openapi+json")
    assert schema.status_code == 200
    paths = json.loads(schema.content)["paths"]
    for helper in HELPERS:
        assert "post" in paths[f"/api/patterns/{helper}/"]
