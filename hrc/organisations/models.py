"""An organisation (a plant, a company) and the people in it.

Every object of the other apps hangs off an Organisation; what a user may see
or change is decided by their Membership in that object's organisation.
"""

from django.conf import settings
from django.db import models

from hrc.organisations.choices import AdminAction, Role
from hrc.organisations.validators import validate_cell


class Organisation(models.Model):
    name = models.CharField(
        max_length=200, help_text="The name people know the plant or company by."
    )
    slug = models.SlugField(
        max_length=100,
        unique=True,
        help_text="Short unique identifier used in URLs and scripts (letters, digits, hyphens).",
    )
    created_at = models.DateTimeField(
        auto_now_add=True, help_text="When the organisation was registered."
    )

    class Meta:
        ordering = ["name"]

    def __str__(self) -> str:
        return self.name


class Membership(models.Model):
    """A user's place in one organisation; the role decides what they may change there."""

    user = models.ForeignKey(
        settings.AUTH_USER_MODEL,
        on_delete=models.CASCADE,
        related_name="memberships",
        help_text="The person who belongs to the organisation.",
    )
    organisation = models.ForeignKey(
        Organisation,
        on_delete=models.CASCADE,
        related_name="memberships",
        help_text="The organisation the person belongs to.",
    )
    role = models.CharField(
        max_length=20,
        choices=Role.choices,
        help_text=(
            "Admin: manages people and cobots. Engineer: models and publishes patterns. "
            "Operator: works on the shop floor and only reads models."
        ),
    )
    joined_at = models.DateTimeField(auto_now_add=True, help_text="When the person was added.")
    is_active = models.BooleanField(
        default=True,
        help_text="Whether the person still works here; a deactivated member sees nothing of the organisation.",
    )

    class Meta:
        ordering = ["organisation__name", "user__username"]
        constraints = [
            models.UniqueConstraint(
                fields=["user", "organisation"],
                name="membership_one_per_user_and_organisation",
                violation_error_message="This person is already a member of the organisation.",
            )
        ]

    def __str__(self) -> str:
        return f"{self.user} in {self.organisation} ({self.get_role_display()})"


class Team(models.Model):
    """A named group of members (a shift, a cell crew) inside one organisation."""

    organisation = models.ForeignKey(
        Organisation,
        on_delete=models.CASCADE,
        related_name="teams",
        help_text="The organisation the team belongs to.",
    )
    name = models.CharField(
        max_length=200, help_text="The team's name, unique in its organisation."
    )
    members = models.ManyToManyField(
        Membership,
        blank=True,
        related_name="teams",
        help_text="Members of the team; only members of the same organisation can join.",
    )

    class Meta:
        ordering = ["organisation__name", "name"]
        constraints = [
            models.UniqueConstraint(
                fields=["organisation", "name"],
                name="team_name_unique_in_organisation",
                violation_error_message="The organisation already has a team of this name.",
            )
        ]

    def __str__(self) -> str:
        return f"{self.name} ({self.organisation})"


class Cell(models.Model):
    """A work cell on the floor: where cobots stand and a tablet shows them (/tablet/<name>/)."""

    organisation = models.ForeignKey(
        Organisation,
        on_delete=models.CASCADE,
        related_name="cells",
        help_text="The organisation whose floor the cell is on.",
    )
    name = models.CharField(
        max_length=50,
        validators=[validate_cell],
        help_text="The cell's name, unique in its organisation: letters, digits, - and _ (it is part of the tablet's address).",
    )
    description = models.CharField(
        max_length=300, blank=True, help_text="Where the cell is and what is done there."
    )

    class Meta:
        ordering = ["organisation__name", "name"]
        constraints = [
            models.UniqueConstraint(
                fields=["organisation", "name"],
                name="cell_name_unique_in_organisation",
                violation_error_message="The organisation already has a cell of this name.",
            )
        ]

    def __str__(self) -> str:
        return self.name


class AdminRecord(models.Model):
    """One change an organisation's admin made (a person added, a team renamed): who, what, when."""

    organisation = models.ForeignKey(
        Organisation,
        on_delete=models.CASCADE,
        related_name="admin_records",
        help_text="The organisation that was changed.",
    )
    actor = models.ForeignKey(
        settings.AUTH_USER_MODEL,
        on_delete=models.SET_NULL,
        null=True,
        related_name="+",
        help_text="Who made the change; empty once that user is deleted.",
    )
    action = models.CharField(max_length=40, choices=AdminAction.choices)
    target = models.CharField(
        max_length=200, help_text="What was changed, by name (a username, a team, a cell)."
    )
    detail = models.JSONField(default=dict, blank=True, help_text="The values set.")
    at = models.DateTimeField(auto_now_add=True, db_index=True)

    class Meta:
        ordering = ["-at", "-id"]

    def __str__(self) -> str:
        return f"{self.get_action_display()} {self.target}"


class ApiToken(models.Model):
    """A machine's key to the API, kept only as its SHA-256: a database dump holds no usable key.

    A key is 40 random characters, so a fast hash is as safe as a slow one and costs
    one indexed lookup per request. Each `POST /api/token/` issues a new one; all a
    user's go when their password changes, when they are deactivated and when they
    leave an organisation (hrc.organisations.services).
    """

    digest = models.CharField(max_length=64, unique=True, help_text="SHA-256 of the key, in hex.")
    user = models.ForeignKey(
        settings.AUTH_USER_MODEL, on_delete=models.CASCADE, related_name="api_tokens"
    )
    created_at = models.DateTimeField(auto_now_add=True)
    expires_at = models.DateTimeField(help_text="The key is refused from then on.")

    class Meta:
        ordering = ["-created_at"]

    def __str__(self) -> str:
        return f"API token of {self.user} until {self.expires_at:%Y-%m-%d %H:%M}"
