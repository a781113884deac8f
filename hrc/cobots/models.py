"""A cobot as the organisation knows it: a name, a driver and an endpoint.

A gateway endpoint belongs to one cobot of one organisation (`endpoint_key`,
unique), and a cobot's credentials are a named secret of its own
organisation (CredentialsSecret, encrypted at rest), so no organisation can
reach another's robot by its address or its credentials. CellStop records
each STOP a tablet gave (hrc.cobots.stops).
"""

from collections.abc import Collection

from django.conf import settings
from django.core.exceptions import ValidationError
from django.db import models

from hrc.cobots.choices import (
    DEVICE_KIND_CHOICES,
    CommandOutcome,
    ControlCommand,
    CredentialsKind,
    DriverKind,
)
from hrc.cobots.validators import (
    split_credentials_source,
    validate_credentials_source,
    validate_endpoint,
    validate_secret_name,
)
from hrc.organisations.models import Organisation
from hrc.organisations.validators import validate_cell
from hrc_gateway import endpoints


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
            "The credentials the driver signs in with: 'none', or 'secret:NAME' for a credentials "
            "secret of the organisation (Cobots → Credentials). Never type the secret itself here."
        ),
    )
    # NULL, not "": rows that shared an endpoint before the rule keep NULL, which the
    # unique constraint lets repeat, until someone gives them an endpoint of their own.
    endpoint_key = models.CharField(  # noqa: DJ001
        max_length=600,
        null=True,
        editable=False,
        help_text=(
            "The endpoint as the network sees it (hrc_gateway.endpoints.endpoint_key); unique, so one "
            "gateway is one cobot's. Empty only for a cobot that shared its endpoint before the rule."
        ),
    )
    cell = models.CharField(
        max_length=50,
        blank=True,
        default="",
        validators=[validate_cell],
        help_text=(
            "The work cell the cobot stands in (letters, digits, - and _), registered as one of the "
            "organisation's cells; that cell's tablet shows and stops its cobots. Empty: shown on "
            "the whole floor's tablet, which has no STOP; give it a cell to stop it from one."
        ),
    )
    stopped_at = models.DateTimeField(
        null=True,
        blank=True,
        editable=False,
        help_text="Set while a tablet's STOP holds the cobot paused (hrc.cobots.stops); no job starts.",
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
            ),
            # Two registrations racing past clean() cannot both commit.
            models.UniqueConstraint(
                fields=["endpoint_key"],
                name="cobot_endpoint_registered_once",
                violation_error_message="Another cobot is registered at this gateway endpoint.",
            ),
        ]

    def __str__(self) -> str:
        return self.name

    def save(self, *args: object, **kwargs: object) -> None:
        # Derived here, not in a service only, so that no write path can skip the constraint.
        self.endpoint_key = key_of(self.endpoint)
        update_fields = kwargs.get("update_fields")
        if (
            isinstance(update_fields, list | tuple | set | frozenset)
            and "endpoint" in update_fields
        ):
            kwargs["update_fields"] = {*update_fields, "endpoint_key"}
        super().save(*args, **kwargs)  # type: ignore[arg-type]

    def clean(self) -> None:
        """What needs the database or the network: the endpoint is free and within
        HRC_COBOT_NETWORKS, the credentials secret is the organisation's. The admin's form, the
        pages and the API all reach it through full_clean."""
        errors: dict[str, str] = {}
        key = key_of(self.endpoint)
        if key is not None:
            problem = self._endpoint_taken(key) or endpoint_outside_networks(self.endpoint)
            if problem:
                errors["endpoint"] = problem
        problem = self._unknown_secret()
        if problem:
            errors["credentials_source"] = problem
        if errors:
            raise ValidationError(errors)

    def _endpoint_taken(self, key: str) -> str | None:
        holder = (
            Cobot.objects.filter(endpoint_key=key)
            .exclude(pk=self.pk)
            .values_list("name", "organisation_id")
            .first()
        )
        if holder is None:
            return None
        name, organisation_id = holder
        # Another organisation's cobot is not named: its names are behind the wall.
        whose = (
            f"cobot {name}"
            if organisation_id == self.organisation_id
            else "a cobot of another organisation"
        )
        return (
            f"The gateway at {self.endpoint} is already registered to {whose}: a gateway "
            "endpoint (host and port) belongs to one cobot of one organisation."
        )

    def _unknown_secret(self) -> str | None:
        parts = split_credentials_source(self.credentials_source)
        if parts is None or parts[0] != CredentialsKind.SECRET:
            return None  # 'none', or refused by the field's validator
        exists = CredentialsSecret.objects.filter(
            organisation_id=self.organisation_id, name=parts[1]
        ).exists()
        if exists:
            return None
        return (
            f"The organisation has no credentials secret named {parts[1]}; an admin of the "
            "organisation creates it under Cobots → Credentials."
        )


def key_of(endpoint: str) -> str | None:
    """The endpoint's unique key; None for an endpoint too malformed to have one."""
    try:
        return str(endpoints.endpoint_key(endpoint))
    except endpoints.EndpointError:
        return None


def endpoint_outside_networks(endpoint: str) -> str | None:
    """Why the endpoint is refused under HRC_COBOT_NETWORKS, or None (also when it is unset)."""
    networks = settings.HRC_COBOT_NETWORKS
    if not networks:
        return None
    allowed = ", ".join(str(n) for n in networks)
    try:
        host, port = endpoints.host_and_port(endpoint)
        addresses = endpoints.resolve(host, port)
    except endpoints.EndpointError as error:
        return f"{error} Cobot endpoints must be on the networks {allowed} (HRC_COBOT_NETWORKS)."
    if endpoints.outside(addresses, networks) or not addresses:
        return (
            f"The host {host} is outside the networks cobot endpoints may be on: {allowed} "
            "(HRC_COBOT_NETWORKS)."
        )
    return None


class CredentialsSecret(models.Model):
    """A user name and password an organisation's cobots sign in to their gateways with.

    Set by an admin of the organisation, kept encrypted (hrc.cobots.credentials),
    never shown back; a cobot names it as `secret:NAME`.
    """

    organisation = models.ForeignKey(
        Organisation, on_delete=models.CASCADE, related_name="credentials_secrets"
    )
    name = models.CharField(
        max_length=64,
        validators=[validate_secret_name],
        help_text="How cobots name it: a cobot's credentials source 'secret:NAME'.",
    )
    sealed = models.TextField(
        editable=False, help_text="The user name and password, Fernet-encrypted."
    )
    updated_by = models.ForeignKey(
        settings.AUTH_USER_MODEL,
        on_delete=models.SET_NULL,
        null=True,
        blank=True,
        related_name="+",
        help_text="Who set it last (empty when set from the command line).",
    )
    updated_at = models.DateTimeField(auto_now=True)

    class Meta:
        ordering = ["organisation__name", "name"]
        constraints = [
            models.UniqueConstraint(
                fields=["organisation", "name"],
                name="credentials_secret_name_unique_in_organisation",
                violation_error_message="The organisation already has a secret of this name.",
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


class CellStop(models.Model):
    """A tablet's STOP: every cobot of the cell paused, and no call of the cell's devices
    started, until someone confirms resuming.

    A convenience, not a safety function: the robots' own safety systems stay in
    charge, and nothing here clears a protective or emergency stop.
    """

    organisation = models.ForeignKey(
        Organisation, on_delete=models.CASCADE, related_name="cell_stops"
    )
    cell = models.CharField(max_length=50, blank=True, help_text="Empty: the whole floor.")
    stopped_by = models.ForeignKey(
        settings.AUTH_USER_MODEL, on_delete=models.SET_NULL, null=True, related_name="+"
    )
    stopped_at = models.DateTimeField(auto_now_add=True)
    resumed_by = models.ForeignKey(
        settings.AUTH_USER_MODEL, on_delete=models.SET_NULL, null=True, blank=True, related_name="+"
    )
    resumed_at = models.DateTimeField(null=True, blank=True)
    cobots = models.JSONField(default=list, help_text="The ids of the cobots it paused.")
    problems = models.JSONField(
        default=dict, blank=True, help_text="Cobot id → why it could not be paused or resumed."
    )

    class Meta:
        db_table = "live_cellstop"  # made by the live app, which once kept STOPs
        ordering = ["-stopped_at", "-id"]
        constraints = [
            # One STOP holds a cell at a time: a second press finds the first.
            models.UniqueConstraint(
                fields=["organisation", "cell"],
                condition=models.Q(resumed_at__isnull=True),
                name="cell_stop_one_active_per_cell",
            )
        ]

    def __str__(self) -> str:
        return f"STOP of {self.cell or 'the floor'} at {self.stopped_at:%H:%M:%S}"


class Device(models.Model):
    """A device of a cell (a linear axis, a part detection camera, a display…) with a queue of
    its own: one call at a time, first come first served (hrc.cases.device_jobs).

    Its calls go through the OPC UA gateway of a registered cobot (`gateway`), as the
    prototype's URUA served a cell's devices beside its cobot: credentials and endpoints stay
    in one place, the cobot's.
    """

    organisation = models.ForeignKey(
        Organisation,
        on_delete=models.CASCADE,
        related_name="devices",
        help_text="The organisation that runs this device.",
    )
    name = models.CharField(
        max_length=100, help_text="The device's name, unique in the organisation (e.g. axis1)."
    )
    kind = models.CharField(
        max_length=30,
        choices=DEVICE_KIND_CHOICES,
        help_text="What it does; a task's device call of this kind may run on it.",
    )
    cell = models.CharField(
        max_length=50,
        blank=True,
        default="",
        validators=[validate_cell],
        help_text=(
            "The work cell it stands in; a cobot task of that cell calls it, and the cell's STOP "
            "holds its calls. Empty: the whole floor (with the cobots that have no cell)."
        ),
    )
    gateway = models.ForeignKey(
        Cobot,
        on_delete=models.PROTECT,
        related_name="devices",
        help_text="The registered cobot whose OPC UA gateway serves the device (under Devices/).",
    )
    is_active = models.BooleanField(
        default=True, help_text="Untick to take the device out of service; no call is sent to it."
    )
    created_at = models.DateTimeField(auto_now_add=True)
    updated_at = models.DateTimeField(auto_now=True)

    class Meta:
        ordering = ["organisation__name", "name"]
        constraints = [
            models.UniqueConstraint(
                fields=["organisation", "name"],
                name="device_name_unique_in_organisation",
                violation_error_message="The organisation already has a device of this name.",
            )
        ]

    def __str__(self) -> str:
        return self.name

    def validate_constraints(self, exclude: Collection[str] | None = None) -> None:
        # Its one constraint is about the name: said at the name's field, not above the form.
        try:
            super().validate_constraints(exclude=exclude)
        except ValidationError as error:
            raise ValidationError({"name": error.messages}) from None

    def clean(self) -> None:
        """The gateway is a cobot of the device's own organisation: no calls through another's."""
        if (
            self.gateway_id is not None
            and not Cobot.objects.filter(
                pk=self.gateway_id, organisation_id=self.organisation_id
            ).exists()
        ):
            raise ValidationError({"gateway": "The gateway must be a cobot of the organisation."})
