"""A supervisor reassigns an operator task: to another operator who may do it, or back to its
candidates; whom it may go to; the refusals; the wall (POST /api/work-items/{id}/reassign/,
GET /api/work-items/{id}/performers/)."""

from typing import Any

import pytest
from django.contrib.auth.models import User
from rest_framework.test import APIClient

from hrc.cases.choices import EventType
from hrc.cases.models import Case, CaseEvent, WorkItem
from hrc.organisations import services as organisation_services
from hrc.organisations.choices import Role
from hrc.organisations.models import Organisation
from hrc.patterns.models import PatternVersion
from tests import factories


def _client(user: User) -> APIClient:
    client = APIClient()
    client.force_authenticate(user)
    return client


def _act(client: APIClient, item: WorkItem, action: str, body: Any = None) -> Any:
    return client.post(f"/api/work-items/{item.pk}/{action}/", body, format="json")


def _reassign(client: APIClient, item: WorkItem, user: User | int | None) -> Any:
    target = user.pk if isinstance(user, User) else user
    return _act(client, item, "reassign", {"user": target})


def _state(item: WorkItem) -> tuple[str, str | None]:
    item.refresh_from_db()
    return item.state, item.claimed_by.username if item.claimed_by else None


@pytest.fixture
def colleague(organisation: Organisation) -> User:
    return factories.make_member(organisation, Role.OPERATOR, "carl-colleague")


@pytest.fixture
def shared_case(choice_version: PatternVersion, engineer: User, operator: User, colleague: User) -> Case:  # fmt: skip
    """A case whose first task, count, is offered to the operator and to the colleague."""
    mapping = {"o": {"users": [operator.pk, colleague.pk]}}
    return factories.make_case(choice_version, started_by=engineer, actor_mapping=mapping)


def test_an_engineer_hands_a_claimed_task_to_a_colleague_and_the_log_says_who_did(
    engineer_client: APIClient, shared_case: Case, operator: User, colleague: User, engineer: User
) -> None:
    item = factories.open_work_item(shared_case, "count")
    assert _act(_client(operator), item, "claim").status_code == 200

    answer = _reassign(engineer_client, item, colleague)

    assert answer.status_code == 200, answer.data
    assert (answer.data["state"], answer.data["claimed_by"]) == ("claimed", colleague.username)
    assert _state(item) == ("claimed", colleague.username)
    event = CaseEvent.objects.filter(case=shared_case).latest("seq")
    assert (event.type, event.user, event.work_item_id) == (EventType.TASK_REASSIGNED, engineer, item.pk)  # fmt: skip
    assert event.detail == {"from": operator.username, "to": colleague.username}
    # The operator who had it can no longer act on it; the colleague can.
    assert _act(_client(operator), item, "start").status_code == 409
    assert _act(_client(colleague), item, "start").status_code == 200


def test_a_started_task_stays_started_and_its_new_holder_completes_it(
    admin_client: APIClient, shared_case: Case, operator: User, colleague: User
) -> None:
    item = factories.open_work_item(shared_case, "count")
    assert _act(_client(operator), item, "start").status_code == 200

    assert _reassign(admin_client, item, colleague).status_code == 200

    assert _state(item) == ("running", colleague.username)
    refused = _act(_client(operator), item, "complete", {"data": {"count": 4}})
    assert (refused.status_code, refused.data["detail"]) == (409, "count parts is being done by someone else.")  # fmt: skip
    done = _act(_client(colleague), item, "complete", {"data": {"count": 4}})
    assert done.status_code == 200, done.data
    assert done.data["completed_by"] == colleague.username
    shared_case.refresh_from_db()
    assert shared_case.data == {"count": {"count": 4}}


def test_a_claimed_task_goes_back_to_its_candidates_and_an_offered_one_to_someone(
    engineer_client: APIClient, shared_case: Case, operator: User, colleague: User
) -> None:
    item = factories.open_work_item(shared_case, "count")
    _act(_client(operator), item, "claim")

    assert _reassign(engineer_client, item, None).status_code == 200
    assert _state(item) == ("offered", None)
    assert CaseEvent.objects.filter(case=shared_case).latest("seq").detail == {
        "from": operator.username,
        "to": None,
    }
    assert _reassign(engineer_client, item, colleague).status_code == 200
    assert _state(item) == ("claimed", colleague.username)


def test_what_a_reassignment_refuses_says_why_and_changes_nothing(
    engineer_client: APIClient,
    shared_case: Case,
    operator: User,
    colleague: User,
    organisation: Organisation,
    outsider: User,
) -> None:
    item = factories.open_work_item(shared_case, "count")
    stranger = factories.make_member(organisation, Role.OPERATOR, "sam-stranger")  # no candidate
    colleague.is_active = False
    colleague.save()
    offered = {
        None: (409, "Nobody holds count parts: name who should do it."),
        stranger.pk: (
            400,
            "sam-stranger may not do count parts: not among its candidates or in its team.",
        ),
        outsider.pk: (400, f"There is no user {outsider.pk} in this organisation."),
        colleague.pk: (400, "carl-colleague cannot sign in any more: choose someone who can."),
        10**9: (400, f"There is no user {10**9} in this organisation."),
    }
    for target, expected in offered.items():
        answer = _reassign(engineer_client, item, target)
        assert (answer.status_code, answer.data["detail"]) == expected
    _act(_client(operator), item, "start")
    for target, expected in {
        None: (409, "count parts has started: name who finishes it."),
        operator.pk: (409, "olivia-operator holds count parts already."),
    }.items():
        answer = _reassign(engineer_client, item, target)
        assert (answer.status_code, answer.data["detail"]) == expected
    assert _state(item) == ("running", operator.username)
    assert not CaseEvent.objects.filter(case=shared_case, type=EventType.TASK_REASSIGNED).exists()
    missing = _act(engineer_client, item, "reassign", {})
    assert (missing.status_code, list(missing.data["fields"])) == (400, ["user"])

    _act(_client(operator), item, "complete", {"data": {"count": 1}})
    answer = _reassign(engineer_client, item, colleague)
    assert (answer.status_code, answer.data["detail"]) == (409, "count parts cannot be reassigned: it is completed now.")  # fmt: skip


def test_a_cobot_task_is_not_reassigned(engineer_client: APIClient, step_case: Case, operator: User) -> None:  # fmt: skip
    item = factories.open_work_item(step_case, "tc1")
    answer = _reassign(engineer_client, item, operator)
    assert answer.status_code == 409
    assert "done by a cobot" in answer.data["detail"]


def test_an_operator_may_not_reassign_and_an_outsider_learns_nothing(
    shared_case: Case, operator: User, colleague: User, outsider: User
) -> None:
    item = factories.open_work_item(shared_case, "count")
    _act(_client(operator), item, "claim")

    mine = _reassign(_client(operator), item, colleague)
    theirs = _reassign(_client(outsider), item, outsider)
    malformed = _act(_client(outsider), item, "reassign", {"user": None})

    assert mine.status_code == 403
    assert (theirs.status_code, theirs.data["detail"]) == (404, f"There is no work item {item.pk} in your organisations.")  # fmt: skip
    assert malformed.status_code == 404
    assert _client(operator).post("/api/work-items/x1/reassign/", {"user": None}, format="json").status_code == 404  # fmt: skip
    assert _state(item) == ("claimed", operator.username)


def test_the_performers_are_the_candidates_and_the_teams_active_members_of_ours(
    engineer_client: APIClient,
    shared_case: Case,
    choice_version: PatternVersion,
    engineer: User,
    operator: User,
    colleague: User,
    organisation: Organisation,
    other_organisation: Organisation,
) -> None:
    item = factories.open_work_item(shared_case, "count")
    answer = engineer_client.get(f"/api/work-items/{item.pk}/performers/")
    assert answer.status_code == 200, answer.data
    assert answer.data == [
        {"id": colleague.pk, "username": "carl-colleague"},
        {"id": operator.pk, "username": "olivia-operator"},
    ]

    team = organisation_services.create_team(organisation, name="Shift B")
    gone = factories.make_member(organisation, Role.OPERATOR, "gus-gone")
    organisation_services.set_team_members(team, [colleague.memberships.get(), gone.memberships.get()])  # fmt: skip
    gone.is_active = False
    gone.save()
    factories.make_member(other_organisation, Role.OPERATOR, "their-operator")
    by_team = factories.make_case(choice_version, started_by=engineer, actor_mapping={"o": {"team": "Shift B"}})  # fmt: skip
    team_item = factories.open_work_item(by_team, "count")
    answer = engineer_client.get(f"/api/work-items/{team_item.pk}/performers/")
    assert [row["username"] for row in answer.data] == ["carl-colleague"]


def test_only_engineers_and_admins_of_ours_see_the_performers(
    shared_case: Case, operator: User, outsider: User, step_case: Case, engineer_client: APIClient
) -> None:
    item = factories.open_work_item(shared_case, "count")
    url = f"/api/work-items/{item.pk}/performers/"
    assert _client(operator).get(url).status_code == 403
    assert _client(outsider).get(url).status_code == 404
    step = factories.open_work_item(step_case, "tc1")
    answer = engineer_client.get(f"/api/work-items/{step.pk}/performers/")
    assert answer.status_code == 409
