"""A pattern model (the engineer's editable draft) and its published versions.

A PatternVersion is a frozen copy of a draft that passed the check, numbered
1, 2, 3… per pattern. Cases will run against versions, never against drafts,
so a version is never changed or deleted once published.
"""

from typing import Any

from django.conf import settings
from django.db import models

from hrc.organisations.choices import Role
from hrc.organisations.models import Organisation
from hrc.patterns.documents import validate_storable_document


class PatternModel(models.Model):
    organisation = models.ForeignKey(
        Organisation,
        on_delete=models.CASCADE,
        related_name="patterns",
        help_text="The organisation that owns the pattern; only its members can see it.",
    )
    name = models.CharField(max_length=200, help_text="The name the pattern is listed under.")
    description = models.TextField(
        blank=True, help_text="What the pattern is for: the cell, the workpiece, the use case."
    )
    draft = models.JSONField(
        validators=[validate_storable_document],
        help_text=(
            "The work-in-progress model as an hrc-pattern/1 JSON document. It must have the "
            "right shape but may still break the model's rules; publishing checks it fully."
        ),
    )
    created_by = models.ForeignKey(
        settings.AUTH_USER_MODEL,
        on_delete=models.SET_NULL,
        null=True,
        blank=True,
        related_name="+",
        help_text="Who created the pattern.",
    )
    created_at = models.DateTimeField(auto_now_add=True, help_text="When the pattern was created.")
    updated_at = models.DateTimeField(auto_now=True, help_text="When the draft was last saved.")
    archived_at = models.DateTimeField(
        null=True,
        blank=True,
        help_text="Set while the pattern is archived: listed only on request; its versions stay.",
    )

    class Meta:
        ordering = ["organisation__name", "name", "id"]
        verbose_name = "pattern"

    def __str__(self) -> str:
        return self.name


def default_start_roles() -> list[str]:
    return [Role.ADMIN.value, Role.ENGINEER.value]


class ImmutableVersionError(Exception):
    """A published version was about to be changed; versions are written once."""


class PatternVersion(models.Model):
    pattern = models.ForeignKey(
        PatternModel,
        # Published versions are the record cases run against: they block deletion.
        on_delete=models.PROTECT,
        related_name="versions",
        help_text="The pattern this is a published version of.",
    )
    number = models.PositiveIntegerField(
        help_text="1 for the first publication of the pattern, then 2, 3, …"
    )
    document = models.JSONField(help_text="The hrc-pattern/1 document exactly as published.")
    report = models.JSONField(
        help_text="The engine's check report at publication: patterns found, soundness, warnings."
    )
    published_by = models.ForeignKey(
        settings.AUTH_USER_MODEL,
        on_delete=models.PROTECT,
        related_name="+",
        help_text="Who published this version.",
    )
    published_at = models.DateTimeField(auto_now_add=True, help_text="When it was published.")
    default_actor_mapping = models.JSONField(
        default=dict,
        blank=True,
        help_text=(
            "Who performs each actor unless a case says otherwise: {actor: {users: [...]} | "
            "{team: ...} | {cobot: ...}}. The one setting of a version that may change "
            "(services.set_default_actor_mapping); the document and report never do."
        ),
    )
    # Who may start cases is the organisation's business, not the document's, so it
    # changes on a published version as the mapping does.
    start_roles = models.JSONField(
        default=default_start_roles,
        blank=True,
        help_text="The roles that may start its cases: admin, engineer, operator.",
    )
    start_cells = models.JSONField(
        default=list,
        blank=True,
        help_text="The cells whose tablets offer operators to start a case (with 'operator' in start_roles).",
    )
    retired_at = models.DateTimeField(
        null=True,
        blank=True,
        help_text="Set while the version is retired: it starts no new case; running ones go on.",
    )

    class Meta:
        ordering = ["pattern", "-number"]
        verbose_name = "published version"
        constraints = [
            models.UniqueConstraint(fields=["pattern", "number"], name="version_number_unique")
        ]

    def __str__(self) -> str:
        return f"{self.pattern} v{self.number}"

    def save(self, *args: Any, **kwargs: Any) -> None:
        # The last line of defence; services, admin and API offer no update path anyway.
        if not self._state.adding:
            raise ImmutableVersionError(f"{self} is published and cannot be changed.")
        super().save(*args, **kwargs)
