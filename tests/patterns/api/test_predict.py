"""POST /api/patterns/predict/: a draft predicted by simulation, with given, measured and
simulated times; the wall around the measurements; bad input named."""

import json
from pathlib import Path
from typing import Any

import pytest
from django.contrib.auth.models import User
from rest_framework.test import APIClient

from hrc.organisations.models import Organisation
from tests import factories
from tests.patterns.measured_cases import completed_case, sequence_document

USE_CASES = Path(__file__).resolve().parents[3] / "hrc" / "patterns" / "examples" / "use_cases"


def _post(client: APIClient, body: Any) -> Any:
    return client.post("/api/patterns/predict/", json.dumps(body), content_type="application/json")


def _use_case() -> dict[str, Any]:
    document: dict[str, Any] = json.loads((USE_CASES / "1_spot_taping.json").read_text())
    return document


def test_a_use_case_is_predicted_with_its_bottleneck_and_each_actors_load(
    engineer_client: APIClient,
) -> None:
    response = _post(engineer_client, {"document": _use_case(), "options": {"cases": 50}})

    assert response.status_code == 200, response.data
    prediction = response.data["prediction"]
    assert prediction["cases"] == prediction["completed"] == 50
    assert "trace" not in prediction
    assert prediction["cycle_time"]["p50"] > 0
    assert prediction["bottleneck"] in response.data["durations"]
    assert prediction["critical_path"]
    assert prediction["actors"]
    for load in prediction["actors"]:
        assert 0 <= load["utilisation"] <= 1
    sources = {time["source"] for time in response.data["durations"].values()}
    assert sources == {"assumed", "program"}  # operators by default, cobots by their programs
    assert response.data["compared"] is None


def test_a_given_time_changes_the_cycle_by_what_it_adds(engineer_client: APIClient) -> None:
    def p50(seconds: float) -> float:
        options = {
            "cases": 5,
            "durations": {
                "prep": {"kind": "fixed", "seconds": seconds},
                "pack": {"kind": "triangular", "low": 1, "mode": 2, "high": 4},
            },
        }
        response = _post(engineer_client, {"document": sequence_document(), "options": options})
        assert response.status_code == 200, response.data
        assert response.data["durations"]["prep"]["source"] == "given"
        assert response.data["durations"]["prep"]["describe"] == f"fixed, {seconds} s"
        return float(response.data["prediction"]["cycle_time"]["p50"])

    assert p50(20) == pytest.approx(p50(10) + 10)


@pytest.fixture
def measured_pattern(organisation: Organisation, engineer: User, operator: User) -> Any:
    """A pattern whose published version ran two cases: prep took 4 s and 6 s, pack 10 s."""
    version = factories.make_version(organisation, published_by=engineer, draft=sequence_document())
    for prep in (4, 6):
        completed_case(
            version, engineer=engineer, operator=operator, seconds={"prep": prep, "pack": 10}
        )
    return version.pattern


def test_measured_times_time_the_tasks_no_time_is_given_for(
    engineer_client: APIClient, measured_pattern: Any
) -> None:
    body = {"document": sequence_document(), "pattern": measured_pattern.pk}

    response = _post(engineer_client, body | {"options": {"cases": 200}})

    assert response.status_code == 200, response.data
    prep, pack = response.data["durations"]["prep"], response.data["durations"]["pack"]
    assert prep["source"] == pack["source"] == "measured"
    assert prep["runs"] == 2
    assert prep["matched_by"] == "id"
    assert prep["distribution"]["kind"] == "lognormal"
    assert prep["distribution"]["median"] == pytest.approx((4 * 6) ** 0.5)
    assert pack["describe"] == "fixed, 10 s (2 runs)"
    tasks = {load["task"]: load for load in response.data["prediction"]["tasks"]}
    assert tasks["pack"]["mean_duration"] == 10
    assert 4 < tasks["prep"]["mean_duration"] < 6.5


def test_a_renamed_task_keeps_its_history_by_label_and_measured_false_ignores_it(
    engineer_client: APIClient, measured_pattern: Any
) -> None:
    body = {"document": sequence_document("prepare_1"), "pattern": measured_pattern.pk}

    renamed = _post(engineer_client, body)
    ignored = _post(engineer_client, body | {"options": {"measured": False}})

    assert renamed.data["durations"]["prepare_1"]["matched_by"] == "label"
    assert ignored.data["durations"]["prepare_1"]["source"] == "assumed"


def test_a_published_version_is_predicted_beside_the_draft(
    engineer_client: APIClient, measured_pattern: Any
) -> None:
    version = measured_pattern.versions.get()
    options = {"cases": 20, "durations": {"prep": {"kind": "fixed", "seconds": 50}}}
    body = {"document": sequence_document(), "compare_version": version.pk, "options": options}

    response = _post(engineer_client, body)

    assert response.status_code == 200, response.data
    compared = response.data["compared"]
    assert compared["version"] == {
        "id": version.pk, "number": version.number, "pattern": measured_pattern.pk
    }  # fmt: skip
    assert compared["durations"]["prep"]["source"] == "given"
    assert compared["durations"]["pack"]["source"] == "measured"  # from the version's pattern
    assert response.data["durations"]["pack"]["source"] == "assumed"  # no pattern named
    assert compared["prediction"]["cycle_time"]["p50"] == 60


def test_the_draft_s_times_for_tasks_the_compared_version_lacks_are_left_to_the_draft(
    engineer_client: APIClient, measured_pattern: Any
) -> None:
    version = measured_pattern.versions.get()
    durations = {
        "prepare_1": {"kind": "fixed", "seconds": 7},  # the draft's new task
        "pack": {"kind": "fixed", "seconds": 3},  # a task both have
    }
    options = {"cases": 5, "durations": durations, "measured": False}
    draft = sequence_document("prepare_1")

    response = _post(engineer_client, {"document": draft, "compare_version": version.pk, "options": options})  # fmt: skip

    assert response.status_code == 200, response.data
    assert response.data["prediction"]["cycle_time"]["p50"] == 10
    compared = response.data["compared"]
    assert set(compared["durations"]) == {"prep", "pack"}
    assert compared["durations"]["pack"]["source"] == "given"
    assert compared["durations"]["prep"]["source"] == "assumed"


BAD_OPTIONS = [
    ({"cases": 0}, "cases"),
    ({"cases": 10**7}, "cases"),
    ({"parallel": 1001}, "parallel"),
    ({"durations": {"prep": {"kind": "gamma"}}}, "durations"),
    ({"durations": {"prep": {"kind": "fixed", "seconds": -1}}}, "durations"),
    ({"weights": {"prep": -1}}, "weights"),
    ({"people": {"o": 0}}, "people"),
]


@pytest.mark.parametrize(("options", "field"), BAD_OPTIONS)
def test_a_bad_option_is_a_400_naming_it(
    engineer_client: APIClient, options: dict[str, Any], field: str
) -> None:
    response = _post(engineer_client, {"document": sequence_document(), "options": options})

    assert response.status_code == 400
    assert field in response.data["fields"]["options"]


def test_an_option_naming_no_task_or_actor_of_the_document_is_a_400(
    engineer_client: APIClient,
) -> None:
    options = {"durations": {"nope": {"kind": "fixed", "seconds": 1}}, "people": {"c": 2}}

    response = _post(engineer_client, {"document": sequence_document(), "options": options})

    assert response.status_code == 400
    assert "'nope'" in response.data["fields"]["durations"][0]
    assert "'c'" in response.data["fields"]["people"][0]


def test_no_document_or_an_unreadable_one_or_a_broken_rule_is_a_400(
    engineer_client: APIClient,
) -> None:
    broken = sequence_document()
    broken["processes"][0]["arcs"].append(["p1", "p3"])  # an arc between two places

    missing = _post(engineer_client, {"options": {}})
    unreadable = _post(engineer_client, {"document": {"format": "hrc-pattern/1", "processes": 3}})
    rule = _post(engineer_client, {"document": broken})

    assert missing.status_code == 400
    assert "document" in missing.data["fields"]
    assert unreadable.status_code == 400
    assert unreadable.data["detail"].startswith("The document is not a readable")
    assert rule.status_code == 400
    assert rule.data["code"] == "no-execution-net"
    assert rule.data["errors"]


def test_an_outsider_naming_our_pattern_or_version_finds_nothing(
    outsider_client: APIClient, measured_pattern: Any
) -> None:
    version = measured_pattern.versions.get()
    for named in ({"pattern": measured_pattern.pk}, {"compare_version": version.pk}):
        response = _post(outsider_client, {"document": sequence_document(), **named})
        assert response.status_code == 404
        assert set(response.data) == {"detail"}


def test_an_operator_may_not_predict(operator_client: APIClient) -> None:
    response = _post(operator_client, {"document": sequence_document()})

    assert response.status_code == 403
