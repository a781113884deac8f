"""A cobot as the organisation knows it: a name, a driver and an endpoint.

Credentials are referenced, not stored: `credentials_source` says where the
worker reads them at connect time, so a database dump leaks no secrets.
"""

from django.conf import settings
from django.db import models

from hrc.cobots.choices import CommandOutcome, ControlCommand, DriverKind
from hrc.cobots.validators import validate_credentials_source, validate_endpoint
from hrc.organisations.models import Organisation
from hrc.organisations.validators import validate_cell


class Cobot(models.Model):
    organisation = models.ForeignKey(
        Organisation,
        on_delete=models.CASCADE,
        related_name="cobots",
        help_text="The organisation that runs this cobot.",
    )
    name = models.CharField(
        max_length=100,
        help_text="The name operators see on the tablets, unique in the organisation (e.g. cobot1).",
    )
    driver = models.CharField(
        max_length=20,
        choices=DriverKind.choices,
        default=DriverKind.SIMULATED,
        help_text="Simulated: the built-in OPC UA simulator. UR: a Universal Robots controller.",
    )
    endpoint = models.CharField(
        max_length=500,
        validators=[validate_endpoint],
        help_text="The cobot's OPC UA server, e.g. opc.tcp://cobot1.plant.local:4840.",
    )
    credentials_source = models.CharField(
        max_length=300,
        default="none",
        validators=[validate_credentials_source],
        help_text=(
            "Where the driver reads the credentials: 'none', 'env:VARIABLE_NAME' (an environment "
            "variable of the worker) or 'file:/run/secrets/name'. Never type the secret itself here."
        ),
    )
    cell = models.CharField(
        max_length=50,
        blank=True,
        default="",
        validators=[validate_cell],
        help_text=(
            "The work cell the cobot stands in (letters, digits, - and _), registered as one of the "
            "organisation's cells; that cell's tablet shows and stops its cobots. Empty: the "
            "organisation's whole floor."
        ),
    )
    stopped_at = models.DateTimeField(
        null=True,
        blank=True,
        editable=False,
        help_text="Set while a tablet's STOP holds the cobot paused (hrc.live.services); no job starts.",
    )
    is_active = models.BooleanField(
        default=True,
        help_text="Untick to take the cobot out of service; no work is sent to an inactive cobot.",
    )
    created_at = models.DateTimeField(auto_now_add=True, help_text="When the cobot was registered.")
    updated_at = models.DateTimeField(auto_now=True, help_text="When the cobot was last changed.")

    class Meta:
        ordering = ["organisation__name", "name"]
        constraints = [
            models.UniqueConstraint(
                fields=["organisation", "name"],
                name="cobot_name_unique_in_organisation",
                violation_error_message="The organisation already has a cobot of this name.",
            )
        ]

    def __str__(self) -> str:
        return self.name


class CobotCommand(models.Model):
    """A control command a person gave a cobot (hrc.cobots.control): who, what, when, what came of it.

    Written before the command goes out, so the row shows it while it runs and
    holds the cobot against a second one; never deleted but with its cobot.
    """

    cobot = models.ForeignKey(Cobot, on_delete=models.CASCADE, related_name="commands")
    command = models.CharField(max_length=20, choices=ControlCommand.choices)
    arguments = models.JSONField(
        default=dict, blank=True, help_text='What the command took, e.g. {"program": "pick"}.'
    )
    requested_by = models.ForeignKey(
        settings.AUTH_USER_MODEL,
        on_delete=models.SET_NULL,
        null=True,
        related_name="+",
        help_text="The person who gave the command (empty once their account is deleted).",
    )
    requested_at = models.DateTimeField(auto_now_add=True)
    finished_at = models.DateTimeField(
        null=True, blank=True, help_text="When the cobot answered, or the command was refused."
    )
    outcome = models.CharField(
        max_length=10, choices=CommandOutcome.choices, default=CommandOutcome.RUNNING
    )
    message = models.TextField(
        blank=True, help_text="Why it was refused or failed, in the cobot's words when it said."
    )

    class Meta:
        ordering = ["-requested_at", "-id"]
        indexes = [models.Index(fields=["cobot", "-requested_at"])]

    def __str__(self) -> str:
        return f"{self.get_command_display()} on {self.cobot_id} ({self.outcome})"
