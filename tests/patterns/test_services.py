import threading

import pytest
from django.contrib.auth.models import User
from django.core.exceptions import ValidationError
from django.db import connection

from hrc.engine import FormatError, check_document, read_pattern
from hrc.organisations.choices import Role
from hrc.organisations.models import Organisation
from hrc.patterns import services
from hrc.patterns.models import ImmutableVersionError, PatternModel, PatternVersion
from tests import factories


def test_a_draft_may_break_the_rules_but_not_the_shape(
    organisation: Organisation, engineer: User
) -> None:
    pattern = factories.make_pattern(organisation, draft=factories.document_with_duplicate_ids())
    assert pattern.pk is not None
    with pytest.raises(FormatError) as raised:
        factories.make_pattern(organisation, draft={"format": "hrc-pattern/1", "processes": 3})
    assert {issue.code for issue in raised.value.issues} == {"format"}
    assert PatternModel.objects.count() == 1


def test_a_pattern_created_without_a_draft_starts_from_a_readable_one(
    organisation: Organisation, engineer: User
) -> None:
    pattern = services.create_pattern(organisation, name="Blank", created_by=engineer)
    assert read_pattern(pattern.draft).name == "Blank"
    # Its net works on a workpiece already; what it lacks is what an engineer draws first.
    codes = [(i.code, i.elements) for i in check_document(pattern.draft).errors]
    assert codes == [("no-actors", ("N",))]


def test_a_draft_the_database_cannot_store_is_refused(organisation: Organisation) -> None:
    document = factories.valid_document()
    document["name"] = "nul\x00char"
    with pytest.raises(ValidationError):
        factories.make_pattern(organisation, draft=document)


def test_update_leaves_out_fields_that_are_not_given(
    organisation: Organisation, pattern: PatternModel
) -> None:
    draft_before = pattern.draft
    services.update_pattern(pattern, description="For cell 4")
    pattern.refresh_from_db()
    assert (pattern.name, pattern.description, pattern.draft) == (
        "Hand-over",
        "For cell 4",
        draft_before,
    )


def test_publishing_numbers_versions_one_two_three(pattern: PatternModel, engineer: User) -> None:
    numbers = [services.publish_pattern(pattern, published_by=engineer).number for _ in range(3)]
    assert numbers == [1, 2, 3]


def test_numbering_is_per_pattern(organisation: Organisation, engineer: User) -> None:
    first, second = factories.make_pattern(organisation), factories.make_pattern(organisation)
    services.publish_pattern(first, published_by=engineer)
    assert services.publish_pattern(second, published_by=engineer).number == 1


def test_a_version_keeps_the_report_and_the_document_it_was_published_with(
    pattern: PatternModel, engineer: User
) -> None:
    version = services.publish_pattern(pattern, published_by=engineer)
    edited = factories.valid_document()
    edited["name"] = "Edited later"
    services.update_pattern(pattern, draft=edited)
    version.refresh_from_db()
    assert version.document["name"] == "Hand-over (1 operator, 1 cobot)"
    assert version.report["valid"] is True
    assert version.report["patterns"] == ["synchronized"]
    assert version.published_by == engineer


def test_a_draft_with_duplicate_ids_is_not_published(
    organisation: Organisation, engineer: User
) -> None:
    pattern = factories.make_pattern(organisation, draft=factories.document_with_duplicate_ids())
    with pytest.raises(services.PublishRefused) as refused:
        services.publish_pattern(pattern, published_by=engineer)
    assert "duplicate-id" in {error["code"] for error in refused.value.report["errors"]}
    assert not PatternVersion.objects.exists()


def test_an_unsound_draft_is_not_published(organisation: Organisation, engineer: User) -> None:
    pattern = factories.make_pattern(organisation, draft=factories.unsound_document())
    with pytest.raises(services.PublishRefused) as refused:
        services.publish_pattern(pattern, published_by=engineer)
    assert refused.value.report["sound"] is False
    assert not PatternVersion.objects.exists()


def test_a_published_version_cannot_be_saved_again(pattern: PatternModel, engineer: User) -> None:
    version = services.publish_pattern(pattern, published_by=engineer)
    version.document = {"tampered": True}
    with pytest.raises(ImmutableVersionError):
        version.save()
    version.refresh_from_db()
    assert version.document["format"] == "hrc-pattern/1"


def test_a_published_pattern_cannot_be_deleted(pattern: PatternModel, engineer: User) -> None:
    services.publish_pattern(pattern, published_by=engineer)
    with pytest.raises(services.PatternHasVersions):
        services.delete_pattern(pattern)
    assert PatternModel.objects.filter(pk=pattern.pk).exists()


def test_an_unpublished_pattern_can_be_deleted(pattern: PatternModel) -> None:
    services.delete_pattern(pattern)
    assert not PatternModel.objects.filter(pk=pattern.pk).exists()


def test_import_names_the_pattern_after_the_document(
    organisation: Organisation, engineer: User
) -> None:
    pattern = services.import_pattern(
        organisation, document=factories.valid_document(), created_by=engineer
    )
    assert pattern.name == "Hand-over (1 operator, 1 cobot)"
    untitled = factories.valid_document()
    del untitled["name"]
    assert services.import_pattern(organisation, document=untitled, created_by=engineer).name == (
        "Imported pattern"
    )


@pytest.mark.django_db(transaction=True)
def test_concurrent_publishes_get_distinct_consecutive_numbers() -> None:
    organisation = factories.make_organisation()
    engineer = factories.make_member(organisation, Role.ENGINEER)
    pattern = factories.make_pattern(organisation)
    publishers = 6
    start = threading.Barrier(publishers)
    numbers: list[int] = []
    failures: list[BaseException] = []

    def publish() -> None:
        try:
            start.wait()
            numbers.append(services.publish_pattern(pattern, published_by=engineer).number)
        except BaseException as exc:  # collected and asserted on below
            failures.append(exc)
        finally:
            connection.close()

    threads = [threading.Thread(target=publish) for _ in range(publishers)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert failures == []
    assert sorted(numbers) == list(range(1, publishers + 1))
