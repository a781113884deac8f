import pytest
from django.contrib.auth.models import User
from django.core.exceptions import ValidationError

from hrc.cases import services as case_services
from hrc.cases.choices import EventType, WorkItemState
from hrc.cases.models import CaseEvent, WorkItem
from hrc.errors import NotFound
from hrc.organisations import services
from hrc.organisations.choices import Role
from hrc.organisations.models import Membership, Organisation
from hrc.organisations.selectors import (
    may_write_in,
    organisations_of,
    role_in,
    writable_organisations,
)
from tests import factories


def test_a_user_can_be_a_member_only_once_per_organisation(
    organisation: Organisation, engineer: User
) -> None:
    with pytest.raises(ValidationError):
        services.add_member(organisation, engineer, Role.OPERATOR)
    assert Membership.objects.filter(user=engineer).count() == 1


def test_the_same_user_may_join_a_second_organisation(
    engineer: User, other_organisation: Organisation
) -> None:
    services.add_member(other_organisation, engineer, Role.OPERATOR)
    assert role_in(engineer, other_organisation.pk) == Role.OPERATOR


def test_an_unknown_role_is_refused(organisation: Organisation) -> None:
    with pytest.raises(ValidationError):
        services.add_member(organisation, factories.make_user(), "superhero")


def test_change_role_changes_what_the_member_may_write(
    organisation: Organisation, operator: User
) -> None:
    assert not may_write_in(operator, organisation.pk)
    membership = Membership.objects.get(user=operator)
    services.change_role(membership, Role.ENGINEER)
    assert may_write_in(operator, organisation.pk)


def test_a_taken_slug_is_refused(organisation: Organisation) -> None:
    with pytest.raises(ValidationError):
        services.create_organisation(name="Copy", slug=organisation.slug)


def test_team_members_must_belong_to_the_teams_organisation(
    organisation: Organisation, engineer: User, outsider: User
) -> None:
    team = services.create_team(organisation, name="Early shift")
    stranger = Membership.objects.get(user=outsider)
    with pytest.raises(ValidationError):
        services.set_team_members(team, [stranger])
    services.set_team_members(team, [Membership.objects.get(user=engineer)])
    assert list(team.members.values_list("user__username", flat=True)) == [engineer.username]


def test_team_names_are_unique_within_an_organisation_only(
    organisation: Organisation, other_organisation: Organisation
) -> None:
    services.create_team(organisation, name="Cell 1")
    services.create_team(other_organisation, name="Cell 1")
    with pytest.raises(ValidationError):
        services.create_team(organisation, name="Cell 1")


@pytest.mark.django_db
def test_provision_user_resets_the_password_and_flags_of_an_existing_user() -> None:
    first = services.provision_user("dana", password="one-password", is_staff=True)
    again = services.provision_user("dana", password="two-password")
    again.refresh_from_db()
    assert again.pk == first.pk
    assert again.check_password("two-password")
    assert not again.check_password("one-password")
    assert not again.is_staff


def test_selectors_see_only_the_users_own_organisations(
    organisation: Organisation, other_organisation: Organisation, operator: User, engineer: User
) -> None:
    assert list(organisations_of(operator)) == [organisation]
    assert list(writable_organisations(operator)) == []
    assert list(writable_organisations(engineer)) == [organisation]
    assert role_in(engineer, other_organisation.pk) is None


# Deactivation hands the person's tasks back ---------------------------------------


def test_deactivating_an_operator_gives_their_claimed_tasks_back_and_leaves_started_ones_to_hand_over(
    organisation: Organisation, engineer: User, operator: User, admin: User
) -> None:
    version = factories.make_version(organisation, published_by=engineer)
    mapping = {"o": {"users": [operator.pk]}, "c": {"cobot": factories.make_cobot(organisation).pk}}
    claimed_case = factories.make_case(version, started_by=engineer, actor_mapping=mapping)
    started_case = factories.make_case(version, started_by=engineer, actor_mapping=mapping)
    claimed = case_services.claim_work_item(factories.open_work_item(claimed_case, "to1"), user=operator)  # fmt: skip
    started = case_services.start_work_item(factories.open_work_item(started_case, "to1"), user=operator)  # fmt: skip

    handed_back = services.deactivate_member(Membership.objects.get(user=operator), by=admin)

    assert handed_back == 1
    item = WorkItem.objects.get(pk=claimed.pk)
    assert item.state == WorkItemState.OFFERED
    assert item.claimed_by is None
    event = CaseEvent.objects.filter(case_id=item.case_id, type=EventType.TASK_REASSIGNED).get()  # fmt: skip
    assert event.user == admin
    # Its start has fired in the net: it waits, held, for a supervisor to hand it over.
    running = WorkItem.objects.get(pk=started.pk)
    assert (running.state, running.claimed_by) == (WorkItemState.RUNNING, operator)
    colleague = factories.make_member(organisation, Role.OPERATOR)
    running.candidates.add(colleague)
    case_services.reassign_work_item(running, by=engineer, to=colleague)
    running.refresh_from_db()
    assert (running.state, running.claimed_by) == (WorkItemState.RUNNING, colleague)


def test_a_person_deactivated_here_but_active_elsewhere_cannot_claim_work_here(
    organisation: Organisation,
    other_organisation: Organisation,
    engineer: User,
    operator: User,
    admin: User,
) -> None:
    services.add_member(other_organisation, operator, Role.OPERATOR)
    version = factories.make_version(organisation, published_by=engineer)
    mapping = {"o": {"users": [operator.pk]}, "c": {"cobot": factories.make_cobot(organisation).pk}}
    case = factories.make_case(version, started_by=engineer, actor_mapping=mapping)
    services.deactivate_member(Membership.objects.get(user=operator, organisation=organisation), by=admin)  # fmt: skip
    operator.refresh_from_db()
    assert operator.is_active  # still signs in for the other organisation

    with pytest.raises(NotFound):
        case_services.claim_work_item(factories.open_work_item(case, "to1"), user=operator)
    assert factories.open_work_item(case, "to1").state == WorkItemState.OFFERED
