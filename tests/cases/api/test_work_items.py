"""The task list and work item actions: claim, unclaim, start, complete; forms, choices, conflicts."""

from typing import Any

import pytest
from django.contrib.auth.models import User
from rest_framework.test import APIClient

from hrc.cases import jobs
from hrc.cases.choices import CaseStatus, EventType, WorkItemState
from hrc.cases.models import Case, Job, WorkItem
from hrc.cobots.models import Cobot
from hrc.organisations import services as organisation_services
from hrc.organisations.choices import Role
from hrc.organisations.models import Organisation
from hrc.patterns.models import PatternVersion
from tests import factories


def _client(user: User) -> APIClient:
    client = APIClient()
    client.force_authenticate(user)
    return client


def _tasks(client: APIClient, query: str = "") -> list[str]:
    response = client.get(f"/api/work-items/{query}")
    assert response.status_code == 200, response.data
    return [item["task"] for item in response.data["results"]]


def _act(client: APIClient, item: WorkItem, action: str, body: Any = None) -> Any:
    return client.post(f"/api/work-items/{item.pk}/{action}/", body, format="json")


@pytest.fixture
def colleague(organisation: Organisation) -> User:
    """A second operator of the home organisation."""
    return factories.make_member(organisation, Role.OPERATOR, "carl-colleague")


# The task list ---------------------------------------------------------------------------


def test_the_task_list_shows_what_is_offered_to_me_and_not_to_others(
    operator_client: APIClient, choice_case: Case, colleague: User
) -> None:
    assert _tasks(operator_client) == ["count"]
    assert _tasks(_client(colleague)) == []


def test_a_team_member_sees_a_task_offered_to_the_team(
    organisation: Organisation, choice_version: PatternVersion, engineer: User, colleague: User
) -> None:
    team = organisation_services.create_team(organisation, name="Shift A")
    organisation_services.set_team_members(team, colleague.memberships.all())
    case = factories.make_case(
        choice_version, started_by=engineer, actor_mapping={"o": {"team": "Shift A"}}
    )
    client = _client(colleague)
    assert _tasks(client) == ["count"]
    item = factories.open_work_item(case, "count")
    assert _act(client, item, "start").status_code == 200


def test_the_task_list_is_one_query_whatever_its_length(
    operator_client: APIClient,
    choice_case: Case,
    engineer: User,
    operator: User,
    django_assert_num_queries: Any,
) -> None:
    for _ in range(3):
        factories.make_case(
            choice_case.version, started_by=engineer, actor_mapping={"o": {"users": [operator.pk]}}
        )
    with django_assert_num_queries(2):  # the page's count, and the page
        assert len(operator_client.get("/api/work-items/").data["results"]) == 4


def test_a_task_claimed_by_someone_else_leaves_my_list(
    operator_client: APIClient, choice_case: Case, colleague: User, engineer: User
) -> None:
    case_both = factories.make_case(
        choice_case.version,
        started_by=engineer,
        actor_mapping={"o": {"users": [colleague.pk, "olivia-operator"]}},
    )
    item = factories.open_work_item(case_both, "count")
    assert _act(_client(colleague), item, "claim").status_code == 200
    assert [i["case"] for i in operator_client.get("/api/work-items/").data["results"]] == [
        choice_case.pk
    ]
    assert _tasks(_client(colleague), f"?case={case_both.pk}") == ["count"]


def test_the_task_list_filters_by_case(
    operator_client: APIClient, choice_case: Case, engineer: User, operator: User
) -> None:
    other = factories.make_case(
        choice_case.version, started_by=engineer, actor_mapping={"o": {"users": [operator.pk]}}
    )
    response = operator_client.get(f"/api/work-items/?case={other.pk}")
    assert [i["case"] for i in response.data["results"]] == [other.pk]
    assert operator_client.get("/api/work-items/?case=x").status_code == 400
    assert operator_client.get("/api/work-items/?kind=robot").status_code == 400


def test_the_detail_has_the_form_and_the_instructions(
    operator_client: APIClient, choice_case: Case
) -> None:
    item = factories.open_work_item(choice_case, "count")
    response = operator_client.get(f"/api/work-items/{item.pk}/")
    assert response.status_code == 200
    assert response.data["form"] == factories.COUNT_FORM
    assert response.data["instructions"] == "Count the parts on the tray."
    assert (response.data["label"], response.data["job"]) == ("count parts", None)


# Claim, start, complete ----------------------------------------------------------------


def test_an_operator_claims_starts_and_completes_a_task_and_the_case_moves_on(
    operator_client: APIClient, choice_case: Case, operator: User
) -> None:
    item = factories.open_work_item(choice_case, "count")
    claimed = _act(operator_client, item, "claim")
    assert (claimed.status_code, claimed.data["state"], claimed.data["claimed_by"]) == (
        200,
        "claimed",
        operator.username,
    )
    assert _act(operator_client, item, "start").data["state"] == "running"
    done = _act(operator_client, item, "complete", {"data": {"count": 12}})
    assert done.status_code == 200, done.data
    assert (done.data["state"], done.data["result"], done.data["completed_by"]) == (
        "completed",
        {"count": 12},
        operator.username,
    )
    choice_case.refresh_from_db()
    assert choice_case.data == {"count": {"count": 12}}
    assert sorted(_tasks(operator_client)) == ["fix", "rework"]


@pytest.mark.parametrize("action", ["claim", "start", "complete"])
def test_an_actions_answer_is_the_work_item_as_read_afterwards(
    operator_client: APIClient, choice_case: Case, action: str
) -> None:
    # The answer is built from the service's copy, not read again: it must not differ.
    item = factories.open_work_item(choice_case, "count")
    steps = ["claim", "start", "complete"]
    for earlier in steps[: steps.index(action)]:
        _act(operator_client, item, earlier)
    answer = _act(operator_client, item, action, {"data": {"count": 3}})
    assert answer.status_code == 200, answer.data
    assert answer.data == operator_client.get(f"/api/work-items/{item.pk}/").data


def test_unclaim_gives_the_task_back(
    operator_client: APIClient, choice_case: Case, colleague: User, engineer: User
) -> None:
    case = factories.make_case(
        choice_case.version,
        started_by=engineer,
        actor_mapping={"o": {"users": [colleague.pk, "olivia-operator"]}},
    )
    item = factories.open_work_item(case, "count")
    _act(_client(colleague), item, "claim")
    refused = _act(operator_client, item, "unclaim")
    assert refused.status_code == 409
    assert "cannot be unclaimed by you" in refused.data["detail"]
    response = _act(_client(colleague), item, "unclaim")
    assert (response.status_code, response.data["state"]) == (200, "offered")
    assert _act(operator_client, item, "claim").status_code == 200


@pytest.mark.parametrize(
    ("data", "named"),
    [
        ({}, "count: an answer is required"),
        ({"count": 0}, "count: 0 is less than the minimum of 1"),
        ({"count": "many"}, "count: 'many' is not of type 'integer'"),
    ],
)
def test_a_completion_the_form_refuses_is_a_400_naming_the_field(
    operator_client: APIClient, choice_case: Case, data: dict[str, Any], named: str
) -> None:
    item = factories.open_work_item(choice_case, "count")
    _act(operator_client, item, "start")
    response = _act(operator_client, item, "complete", {"data": data})
    assert response.status_code == 400
    assert named in response.data["detail"]
    item.refresh_from_db()
    assert item.state == WorkItemState.RUNNING


ANSWER_FORM: dict[str, Any] = {
    "type": "object",
    "required": ["seated", "quality"],
    "properties": {
        "seated": {"type": "boolean", "title": "Part seated?"},
        "quality": {"title": "Quality", "enum": ["OK", "NOK"]},
        "note": {"type": "string"},
        "spare": {"type": "integer", "default": 2},
    },
}


@pytest.fixture
def answer_case(organisation: Organisation, engineer: User, operator: User) -> Case:
    """The choice case, its count task asking a required yes/no and a required choice."""
    document = factories.choice_document()
    document["processes"][0]["transitions"][0]["task"]["form"] = ANSWER_FORM
    version = factories.make_version(organisation, published_by=engineer, draft=document)
    return factories.make_case(
        version, started_by=engineer, actor_mapping={"o": {"users": [operator.pk]}}
    )


def test_a_completion_missing_required_answers_is_refused_at_each_field_and_nothing_is_written(
    operator_client: APIClient, answer_case: Case
) -> None:
    item = factories.open_work_item(answer_case, "count")
    _act(operator_client, item, "start")
    events = answer_case.events.count()
    response = _act(operator_client, item, "complete", {"data": {"quality": "OK"}})
    assert response.status_code == 400
    assert response.data["fields"] == {"seated": ["an answer is required"]}
    assert "seated: an answer is required" in response.data["detail"]
    item.refresh_from_db()
    assert (item.state, item.result, item.completed_by) == (WorkItemState.RUNNING, None, None)
    assert answer_case.events.count() == events
    both = _act(operator_client, item, "complete", {"data": {}})
    assert set(both.data["fields"]) == {"seated", "quality"}


def test_a_completion_stores_exactly_the_answers_given(
    operator_client: APIClient, answer_case: Case
) -> None:
    """No, given, is an answer; the optional fields left out stay out, default or not."""
    item = factories.open_work_item(answer_case, "count")
    _act(operator_client, item, "start")
    response = _act(
        operator_client, item, "complete", {"data": {"seated": False, "quality": "NOK"}}
    )
    assert response.status_code == 200, response.data
    item.refresh_from_db()
    assert item.result == {"seated": False, "quality": "NOK"}


def test_completion_data_that_is_no_object_is_a_400(
    operator_client: APIClient, choice_case: Case
) -> None:
    item = factories.open_work_item(choice_case, "count")
    _act(operator_client, item, "start")
    response = _act(operator_client, item, "complete", {"data": [12]})
    assert response.status_code == 400
    assert "data" in response.data["fields"]


def test_a_deferred_choice_offers_both_tasks_and_starting_one_withdraws_the_other(
    operator_client: APIClient, choice_case: Case
) -> None:
    count = factories.open_work_item(choice_case, "count")
    _act(operator_client, count, "start")
    _act(operator_client, count, "complete", {"data": {"count": 3}})
    fix = factories.open_work_item(choice_case, "fix")
    rework = factories.open_work_item(choice_case, "rework")
    assert _act(operator_client, rework, "start").status_code == 200
    fix.refresh_from_db()
    assert fix.state == WorkItemState.WITHDRAWN
    assert _tasks(operator_client) == ["rework"]
    late = _act(operator_client, fix, "start")
    assert late.status_code == 409
    assert late.data["detail"] == "fix by hand cannot be started: it is withdrawn now."
    assert _act(operator_client, rework, "complete").status_code == 200
    choice_case.refresh_from_db()
    assert choice_case.status == CaseStatus.COMPLETED


# Refusals -----------------------------------------------------------------------------------


def test_a_task_not_offered_to_me_is_a_403(
    engineer_client: APIClient, choice_case: Case, colleague: User
) -> None:
    item = factories.open_work_item(choice_case, "count")
    for client in (engineer_client, _client(colleague)):
        response = _act(client, item, "claim")
        assert response.status_code == 403
        assert response.data["detail"] == "count parts is not offered to you."


@pytest.mark.parametrize("action", ["claim", "unclaim", "start", "complete"])
@pytest.mark.parametrize(
    ("item_id", "detail"),
    [
        ("999999", "There is no work item 999999 in your organisations."),
        # No id at all: no route takes it (hrc.api.routers).
        ("count", "No API endpoint at /api/work-items/count/{action}/."),
        ("-1", "No API endpoint at /api/work-items/-1/{action}/."),
    ],
)
def test_an_action_on_a_work_item_that_is_not_there_is_a_404_naming_it(
    operator_client: APIClient, choice_case: Case, action: str, item_id: str, detail: str
) -> None:
    before = list(WorkItem.objects.values_list("pk", "state"))
    response = operator_client.post(
        f"/api/work-items/{item_id}/{action}/", {"data": {}}, format="json"
    )
    assert response.status_code == 404
    assert response.json()["detail"].startswith(detail.format(action=action))
    assert list(WorkItem.objects.values_list("pk", "state")) == before


def test_conflicts_are_409s_that_say_why(
    operator_client: APIClient, choice_case: Case, colleague: User, engineer: User
) -> None:
    case = factories.make_case(
        choice_case.version,
        started_by=engineer,
        actor_mapping={"o": {"users": [colleague.pk, "olivia-operator"]}},
    )
    item = factories.open_work_item(case, "count")
    assert _act(_client(colleague), item, "start").status_code == 200
    expectations = {
        "claim": "count parts cannot be claimed: it is running now.",
        "start": "count parts cannot be started: it is running now.",
        "complete": "count parts is being done by someone else.",
    }
    for action, detail in expectations.items():
        response = _act(operator_client, item, action, {"data": {"count": 1}})
        assert (response.status_code, response.data["detail"]) == (409, detail)


def test_completing_a_task_that_was_not_started_is_a_409(
    operator_client: APIClient, choice_case: Case
) -> None:
    item = factories.open_work_item(choice_case, "count")
    response = _act(operator_client, item, "complete", {"data": {"count": 1}})
    assert response.status_code == 409
    assert "it is offered now" in response.data["detail"]


# Cobot tasks: read-only, with their job ------------------------------------------------


@pytest.fixture
def cobot(organisation: Organisation) -> Cobot:
    return factories.make_cobot(organisation, name="ur5e-left")


def _hand_over_case(version: PatternVersion, engineer: User, operator: User, cobot: Cobot) -> Case:
    """A hand-over case whose operator task is done: its cobot task is queued for the cobot."""
    case = factories.make_case(
        version,
        started_by=engineer,
        actor_mapping={"o": {"users": [operator.pk]}, "c": {"cobot": cobot.name}},
    )
    client = _client(operator)
    item = factories.open_work_item(case, "to1")
    _act(client, item, "start")
    assert _act(client, item, "complete").status_code == 200
    return case


def test_cobot_tasks_are_listed_read_only_with_their_job_and_queue_position(
    operator_client: APIClient,
    organisation: Organisation,
    engineer: User,
    operator: User,
    cobot: Cobot,
) -> None:
    version = factories.make_version(organisation, published_by=engineer)
    first = _hand_over_case(version, engineer, operator, cobot)
    second = _hand_over_case(version, engineer, operator, cobot)
    response = operator_client.get("/api/work-items/?kind=step,device")
    assert response.status_code == 200
    rows = response.data["results"]
    # The first completion leased its step for the free cobot; the second one's waits.
    assert [(r["case"], r["task"], r["kind"], r["state"]) for r in rows] == [
        (first.pk, "tc1", "step", "running"),
        (second.pk, "tc1", "step", "offered"),
    ]
    assert [
        (r["job"]["state"], r["job"]["queue_position"], r["job"]["cobot_name"]) for r in rows
    ] == [("running", 0, "ur5e-left"), ("queued", 1, "ur5e-left")]
    assert _tasks(operator_client) == []  # the operator's own list has no cobot task
    item = WorkItem.objects.get(pk=rows[0]["id"])
    refused = _act(operator_client, item, "start")
    assert refused.status_code == 409
    assert "done by a cobot" in refused.data["detail"]


def test_a_cobots_queue_lists_the_running_job_then_the_queued_ones_first_come_first_served(
    operator_client: APIClient,
    organisation: Organisation,
    engineer: User,
    operator: User,
    cobot: Cobot,
) -> None:
    version = factories.make_version(organisation, published_by=engineer)
    cases = [_hand_over_case(version, engineer, operator, cobot) for _ in range(3)]
    other_cobot = factories.make_cobot(organisation)
    _hand_over_case(version, engineer, operator, other_cobot)
    lease = jobs.lease_next_job(cobot.pk)  # what a worker does before it drives the cobot
    assert lease is not None
    running = Job.objects.get(pk=lease.job_id)
    assert running.case_id == cases[0].pk
    response = operator_client.get(f"/api/jobs/?cobot={cobot.pk}")
    assert response.status_code == 200
    assert [(j["case"], j["state"], j["queue_position"]) for j in response.data["results"]] == [
        (cases[0].pk, "running", 0),
        (cases[1].pk, "queued", 1),
        (cases[2].pk, "queued", 2),
    ]
    job = response.data["results"][1]
    assert (job["task"], job["label"], job["attempt"], job["waiting_for"]) == (
        "tc1",
        "place insert",
        1,
        "",
    )
    assert len(operator_client.get("/api/jobs/").data["results"]) == 4
    detail = operator_client.get(f"/api/jobs/{running.pk}/")
    assert (detail.status_code, detail.data["queue_position"]) == (200, 0)


def test_a_task_completed_event_is_logged_once_per_completion(
    operator_client: APIClient, choice_case: Case
) -> None:
    item = factories.open_work_item(choice_case, "count")
    _act(operator_client, item, "start")
    _act(operator_client, item, "complete", {"data": {"count": 1}})
    assert _act(operator_client, item, "complete", {"data": {"count": 1}}).status_code == 409
    completed = choice_case.events.filter(type=EventType.TASK_COMPLETED, work_item=item)
    assert completed.count() == 1
