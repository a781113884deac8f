"""POST /api/messages/: correlation, the early-arrival buffer, a repeated message id."""

from typing import Any

import pytest
from django.contrib.auth.models import User
from rest_framework.test import APIClient

from hrc.cases.choices import EventType
from hrc.cases.models import Case, Message
from hrc.organisations.models import Organisation
from hrc.patterns.models import PatternVersion
from tests import factories


@pytest.fixture
def message_version(organisation: Organisation, engineer: User) -> PatternVersion:
    return factories.make_version(
        organisation, published_by=engineer, draft=factories.message_document()
    )


def _case(version: PatternVersion, engineer: User, operator: User, order: str) -> Case:
    return factories.make_case(
        version,
        started_by=engineer,
        actor_mapping={"o": {"users": [operator.pk]}},
        data={"order": order},
    )


def _prepare(operator: User, case: Case) -> None:
    """The operator does the first task: the case then waits for its message."""
    client = APIClient()
    client.force_authenticate(operator)
    item = factories.open_work_item(case, "prepare")
    client.post(f"/api/work-items/{item.pk}/start/")
    assert client.post(f"/api/work-items/{item.pk}/complete/").status_code == 200


def _send(client: APIClient, message_id: str, order: str, **more: Any) -> Any:
    body = {
        "message_id": message_id,
        "name": "part-ready",
        "correlation": {"order": order},
        "payload": {"part": f"part for {order}"},
        **more,
    }
    return client.post("/api/messages/", body, format="json")


def _open_tasks(case: Case) -> list[str]:
    return sorted(case.work_items.filter(state="offered").values_list("task", flat=True))


def test_a_message_reaches_the_waiting_case_whose_correlation_matches(
    engineer_client: APIClient, message_version: PatternVersion, engineer: User, operator: User
) -> None:
    first = _case(message_version, engineer, operator, "A-1")
    second = _case(message_version, engineer, operator, "A-2")
    _prepare(operator, first)
    _prepare(operator, second)
    response = _send(engineer_client, "m-1", "A-2")
    assert response.status_code == 201, response.data
    assert (response.data["case"], response.data["transition"]) == (second.pk, "arrive")
    assert response.data["consumed_at"] is not None
    second.refresh_from_db()
    assert second.data == {"order": "A-2", "part": "part for A-2"}
    assert _open_tasks(second) == ["assemble"]
    assert _open_tasks(first) == []
    received = second.events.get(type=EventType.MESSAGE_RECEIVED)
    assert received.detail == {"message": "m-1", "name": "part-ready"}


def test_an_early_message_waits_until_the_case_reaches_the_message_transition(
    engineer_client: APIClient, message_version: PatternVersion, engineer: User, operator: User
) -> None:
    case = _case(message_version, engineer, operator, "B-7")
    response = _send(engineer_client, "early-1", "B-7", ttl_seconds=600)
    assert response.status_code == 201
    assert (response.data["case"], response.data["consumed_at"]) == (None, None)
    _prepare(operator, case)
    message = Message.objects.get(message_id="early-1")
    assert (message.case_id, message.transition) == (case.pk, "arrive")
    assert _open_tasks(case) == ["assemble"]


def test_a_repeated_message_id_is_harmless_and_answers_with_the_first_message(
    engineer_client: APIClient, message_version: PatternVersion, engineer: User, operator: User
) -> None:
    first_case = _case(message_version, engineer, operator, "C-1")
    second_case = _case(message_version, engineer, operator, "C-1")
    _prepare(operator, first_case)
    _prepare(operator, second_case)
    first = _send(engineer_client, "same-id", "C-1")
    again = _send(engineer_client, "same-id", "C-1")
    assert (first.status_code, again.status_code) == (201, 200)
    assert again.data == first.data
    assert Message.objects.count() == 1
    # One message moved one case; the other still waits.
    waiting = [c for c in (first_case, second_case) if _open_tasks(c) == []]
    assert len(waiting) == 1


def test_a_message_id_reused_for_another_message_is_a_409(
    engineer_client: APIClient, message_version: PatternVersion
) -> None:
    assert _send(engineer_client, "id-1", "A-1").status_code == 201
    reused = _send(engineer_client, "id-1", "B-2")
    assert reused.status_code == 409
    assert "new message needs a new id" in reused.data["detail"]
    assert Message.objects.count() == 1


def test_an_operator_cannot_send_a_message(
    operator_client: APIClient, message_version: PatternVersion
) -> None:
    assert _send(operator_client, "m-op", "A-1").status_code == 403
    assert not Message.objects.exists()


@pytest.mark.parametrize(
    ("body", "field"),
    [
        ({"message_id": "", "name": "part-ready"}, "message_id"),
        ({"message_id": "m", "name": "part-ready", "ttl_seconds": 0}, "ttl_seconds"),
        ({"message_id": "m", "name": "part-ready", "correlation": "A-1"}, "correlation"),
        ({"message_id": "m", "name": "part-ready", "organisation": 99999999}, "organisation"),
    ],
)
def test_a_malformed_message_is_a_400_naming_the_field(
    engineer_client: APIClient, body: dict[str, Any], field: str
) -> None:
    response = engineer_client.post("/api/messages/", body, format="json")
    assert response.status_code == 400
    assert field in response.data["fields"]
