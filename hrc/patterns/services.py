"""Every write to patterns and their versions.

The caller has checked that the acting user may write in the pattern's
organisation (hrc.organisations.selectors.may_write_in); these functions
check the data. Errors:

- FormatError (from the engine): the draft is not `hrc-pattern/1` in shape;
- django.core.exceptions.ValidationError: another field breaks the model's rules;
- PublishRefused (400): the draft does not pass the check, with the report;
- PatternHasVersions (409): a published pattern cannot be deleted.

The last two are refusals of hrc.errors, which the API and the pages answer themselves.
"""

from collections.abc import Iterable
from typing import Any

from django.contrib.auth.models import User
from django.core.exceptions import ValidationError
from django.db import transaction
from django.db.models import Max
from django.utils import timezone

from hrc.errors import Conflict, Invalid
from hrc.organisations.choices import Role
from hrc.organisations.models import Organisation
from hrc.organisations.selectors import cells_of
from hrc.patterns.checking import checked, publish_budget
from hrc.patterns.documents import (
    Report,
    is_publishable,
    read_draft,
    starter_document,
    storage_problem,
)
from hrc.patterns.models import PatternModel, PatternVersion

NAME_LENGTH = PatternModel._meta.get_field("name").max_length or 200


class PublishRefused(Invalid):
    """The draft is not valid or not sound; `report` is the check that says why (400)."""

    code = "check-failed"

    def __init__(self, report: Report) -> None:
        super().__init__(
            "The draft does not pass the check; see the report.", extra={"report": report}
        )
        self.report = report


class PatternHasVersions(Conflict):
    """The pattern has published versions, which are kept as the record cases run against (409)."""

    code = "pattern-has-versions"


def create_pattern(
    organisation: Organisation,
    *,
    name: str,
    created_by: User | None,
    description: str = "",
    draft: object = None,
) -> PatternModel:
    """Creates a pattern with `draft`, or with a starter document when draft is None.

    The draft must have the shape of `hrc-pattern/1`; it may break the rules.
    """
    document = starter_document(name) if draft is None else draft
    _check_draft(document)
    pattern = PatternModel(
        organisation=organisation,
        name=name,
        description=description,
        draft=document,
        created_by=created_by,
    )
    pattern.full_clean(exclude=["draft"])
    pattern.save()
    return pattern


def update_pattern(
    pattern: PatternModel,
    *,
    name: str | None = None,
    description: str | None = None,
    draft: object = None,
) -> PatternModel:
    """Saves the given fields of an existing pattern (None leaves a field as it is).

    Published versions are not touched: they keep the document they were published with.
    """
    changes: dict[str, Any] = {"name": name, "description": description, "draft": draft}
    changes = {field: value for field, value in changes.items() if value is not None}
    if "draft" in changes:
        _check_draft(changes["draft"])
    for field, value in changes.items():
        setattr(pattern, field, value)
    pattern.full_clean(exclude=["draft"])
    pattern.save(update_fields=[*changes, "updated_at"])
    return pattern


def delete_pattern(pattern: PatternModel) -> None:
    """Deletes a pattern that was never published; raises PatternHasVersions otherwise."""
    if pattern.versions.exists():
        raise PatternHasVersions(
            f"{pattern} has published versions; they stay as the record cases run against."
        )
    pattern.delete()


def import_pattern(
    organisation: Organisation,
    *,
    document: object,
    created_by: User | None,
    name: str | None = None,
) -> PatternModel:
    """Creates a pattern from an imported document, named after the document unless `name` is given."""
    titled = document.get("name") if isinstance(document, dict) else None
    chosen = name or (titled if isinstance(titled, str) and titled.strip() else "Imported pattern")
    return create_pattern(
        organisation, name=chosen.strip()[:NAME_LENGTH], created_by=created_by, draft=document
    )


def publish_pattern(pattern: PatternModel, *, published_by: User) -> PatternVersion:
    """Publishes the pattern's current draft as its next version; raises PublishRefused.

    The check runs within the publish budget (hrc.patterns.checking); the caller holds
    one of the organisation's engine slots.

    The draft that is checked is the draft that is published, and concurrent
    publishes number 1, 2, 3… without gaps or collisions (the pattern row lock).
    """
    # The check may take seconds, and on the embedded SQLite a transaction holds the whole
    # database's write lock: check first, and again under the lock only if the draft changed.
    draft = PatternModel.objects.values_list("draft", flat=True).get(pk=pattern.pk)
    report = checked(draft, publish_budget())
    with transaction.atomic():
        locked = PatternModel.objects.select_for_update().get(pk=pattern.pk)
        if locked.draft != draft:
            report = checked(locked.draft, publish_budget())
        if not is_publishable(report):
            raise PublishRefused(report)
        last = locked.versions.aggregate(last=Max("number"))["last"] or 0
        return PatternVersion.objects.create(
            pattern=locked,
            number=last + 1,
            document=locked.draft,
            report=report,
            published_by=published_by,
        )


def archive_pattern(pattern: PatternModel, *, archived: bool) -> PatternModel:
    """Archives the pattern (listed only on request) or brings it back; its versions stay."""
    pattern.archived_at = timezone.now() if archived else None
    PatternModel.objects.filter(pk=pattern.pk).update(archived_at=pattern.archived_at)
    return pattern


def retire_version(version: PatternVersion, *, retired: bool) -> PatternVersion:
    """Retires the version (no new case starts; running ones go on) or puts it back in service."""
    version.retired_at = timezone.now() if retired else None
    PatternVersion.objects.filter(pk=version.pk).update(retired_at=version.retired_at)
    return version


def set_start_rights(
    version: PatternVersion, *, roles: Iterable[str], cells: Iterable[str]
) -> PatternVersion:
    """Sets who may start the version's cases: roles, and the cells whose tablets offer it.

    Raises ValidationError naming `start_roles` or `start_cells` for a role that
    does not exist or a cell the organisation does not have.
    """
    roles, cells = sorted(set(roles)), sorted(set(cells))
    unknown_roles = [role for role in roles if role not in Role.values]
    if unknown_roles:
        raise ValidationError(
            {
                "start_roles": f"No such role: {', '.join(unknown_roles)} (one of {', '.join(Role.values)})."
            }
        )
    known = set(cells_of(version.pattern.organisation_id).values_list("name", flat=True))
    unknown_cells = [cell for cell in cells if cell not in known]
    if unknown_cells:
        raise ValidationError(
            {
                "start_cells": f"{version.pattern.organisation} has no cell {', '.join(unknown_cells)}."
            }
        )
    PatternVersion.objects.filter(pk=version.pk).update(start_roles=roles, start_cells=cells)
    version.start_roles, version.start_cells = roles, cells
    return version


def _check_draft(document: object) -> None:
    """Raises ValidationError when the database cannot store it, FormatError when it is no pattern."""
    problem = storage_problem(document)
    if problem:
        raise ValidationError({"draft": problem})
    read_draft(document)
