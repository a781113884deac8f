"""A version published before a rule existed keeps running; its page says what a new version must fix."""

import pytest
from django.contrib.auth.models import User
from django.test import Client

from hrc.cases.choices import CaseStatus
from hrc.organisations.models import Organisation
from hrc.patterns import services
from hrc.patterns.models import PatternVersion
from tests import factories

pytestmark = pytest.mark.django_db

HEADING = "A new version must fix"


def _browser(user: User) -> Client:
    client = Client()
    client.force_login(user)
    return client


def _choice_without_workpiece_and_with_a_twice_drawn_constraint() -> dict[str, object]:
    """Operators only (so a case runs without a cobot); valid before wpassign and constr were rules."""
    document = factories.choice_document()
    del document["processes"][0]["workpiece"]
    document["actors"].append({"id": "o2", "type": "operator"})
    process = document["processes"][0]
    process["actors"].append("o2")
    process["transitions"][1]["performer"] = "o2"
    document["constraints"] = [{"from": "count", "to": "fix", "type": "time"}] * 2
    return document


@pytest.fixture
def old_version(organisation: Organisation, engineer: User) -> PatternVersion:
    """Written as publishing wrote it before the rules: publishing would refuse it now."""
    document = _choice_without_workpiece_and_with_a_twice_drawn_constraint()
    pattern = factories.make_pattern(organisation, draft=document, created_by=engineer)
    return PatternVersion.objects.create(
        pattern=pattern,
        number=1,
        document=document,
        report={"valid": True, "sound": True, "patterns": [], "errors": [], "warnings": []},
        published_by=engineer,
    )


def test_the_version_page_lists_the_rules_a_new_version_must_fix(
    engineer: User, old_version: PatternVersion
) -> None:
    response = _browser(engineer).get(f"/patterns/versions/{old_version.pk}/")

    assert response.status_code == 200
    html = response.content.decode()
    assert HEADING in html
    assert '<li data-code="unassigned-workpiece">The drawing works on no workpiece' in html
    assert (
        '<li data-code="constraint-duplicate">The time constraint “count parts” → '
        "“fix by hand” is drawn 2 times"
    ) in html


def test_a_version_that_keeps_every_rule_has_nothing_to_fix(
    engineer: User, choice_version: PatternVersion
) -> None:
    response = _browser(engineer).get(f"/patterns/versions/{choice_version.pk}/")

    assert response.status_code == 200
    assert HEADING not in response.content.decode()


def test_an_outsider_sees_nothing_of_the_version(
    outsider: User, old_version: PatternVersion
) -> None:
    response = _browser(outsider).get(f"/patterns/versions/{old_version.pk}/")

    assert response.status_code == 404
    assert "workpiece" not in response.content.decode()


def test_a_case_of_the_old_version_still_starts_and_runs(
    engineer: User, operator: User, old_version: PatternVersion
) -> None:
    case = factories.make_case(
        old_version,
        started_by=engineer,
        actor_mapping={"o": {"users": [operator.pk]}, "o2": {"users": [operator.pk]}},
    )

    assert case.status == CaseStatus.RUNNING
    factories.open_work_item(case, "count")


def test_its_document_is_refused_as_a_new_version(old_version: PatternVersion) -> None:
    with pytest.raises(services.PublishRefused) as refused:
        services.publish_pattern(old_version.pattern, published_by=old_version.published_by)

    codes = {issue["code"] for issue in refused.value.extra["report"]["errors"]}
    assert codes == {"unassigned-workpiece", "constraint-duplicate"}
