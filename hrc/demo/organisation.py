"""The demo organisation: "Demo plant", one person per persona, a team, two simulated cobots
and the devices of the floor they stand on (one of each kind, served by cobot1's gateway).

`manage.py load_demo`, `manage.py demo` and the browser test of the personas
all provision through `provision`, so what the test signs in as is what a
person trying the demo gets. Passwords are generated here with `secrets` and
handed back to the caller to print once; only Django's hash of each is kept.
"""

from __future__ import annotations

import secrets
from collections.abc import Mapping
from dataclasses import dataclass

from django.contrib.auth.models import User
from django.db import transaction

from hrc.cobots import services as cobot_services
from hrc.cobots.choices import DriverKind
from hrc.cobots.models import Cobot, Device
from hrc.engine.taskconfig import DEVICE_KINDS
from hrc.organisations import services as organisation_services
from hrc.organisations.choices import Role
from hrc.organisations.models import Membership, Organisation, Team

ORGANISATION_NAME = "Demo plant"
ORGANISATION_SLUG = "demo-plant"
TEAM_NAME = "Line operators"


@dataclass(frozen=True)
class Persona:
    """A demo user: their role in the demo organisation and the pages they start from.

    Nobody is Django staff: the admin administers the organisation on its own pages
    (/organisation/); /admin/ is for a superuser, whom the demo does not make.
    """

    username: str
    role: Role

    @property
    def pages(self) -> tuple[str, ...]:
        """Paths of the pages this persona works in, first the one to open."""
        if self.role == Role.OPERATOR:
            return ("/tablet/",)
        supervisor = ("/patterns/", "/cases/", "/incidents/", "/analytics/")
        return (*supervisor, "/organisation/people/") if self.role == Role.ADMIN else supervisor


PERSONAS = (
    Persona("admin", Role.ADMIN),
    Persona("engineer", Role.ENGINEER),
    Persona("operator1", Role.OPERATOR),
    Persona("operator2", Role.OPERATOR),
)


@dataclass(frozen=True)
class DemoCobot:
    """A simulated cobot of the demo and the loopback port its gateway serves on by default."""

    name: str
    port: int

    def endpoint(
        self, template: str = "opc.tcp://127.0.0.1:{port}", port: int | None = None
    ) -> str:
        """`template` with {cobot}, {COBOT} (upper case) and {port} filled in."""
        return template.format(cobot=self.name, COBOT=self.name.upper(), port=port or self.port)


DEMO_COBOTS = (DemoCobot("cobot1", 4841), DemoCobot("cobot2", 4842))


@dataclass
class DemoOrganisation:
    organisation: Organisation
    users: dict[str, User]
    # username → the password just set, or None when the user kept theirs (--keep-passwords).
    passwords: dict[str, str | None]
    team: Team
    cobots: list[Cobot]


def generate_password() -> str:
    """16 URL-safe characters (96 bits) from the operating system's randomness."""
    return secrets.token_urlsafe(12)


@transaction.atomic
def provision(
    *,
    endpoints: Mapping[str, str] | None = None,
    credentials: Mapping[str, str] | None = None,
    keep_passwords: bool = False,
) -> DemoOrganisation:
    """Makes the demo organisation complete and returns it with the passwords it set.

    Every persona gets a new generated password unless `keep_passwords` and
    the user already has one. Each demo cobot is (re)pointed at its gateway:
    `endpoints` and `credentials` (a credentials source) by cobot name, by
    default its loopback port (DemoCobot.port) without security, as `make
    demo` serves them. Safe to call again: nothing is duplicated. Raises
    ValidationError for an endpoint or source the cobot model refuses.
    """
    organisation = Organisation.objects.filter(slug=ORGANISATION_SLUG).first()
    if organisation is None:
        organisation = organisation_services.create_organisation(
            name=ORGANISATION_NAME, slug=ORGANISATION_SLUG
        )
    users: dict[str, User] = {}
    passwords: dict[str, str | None] = {}
    for persona in PERSONAS:
        users[persona.username], passwords[persona.username] = _ensure_member(
            organisation, persona, keep_passwords
        )
    team = _ensure_team(
        organisation, [users[p.username] for p in PERSONAS if p.role == Role.OPERATOR]
    )
    endpoints, credentials = endpoints or {}, credentials or {}
    cobots = [
        _ensure_cobot(
            organisation,
            cobot.name,
            endpoints.get(cobot.name) or cobot.endpoint(),
            credentials.get(cobot.name) or "none",
        )
        for cobot in DEMO_COBOTS
    ]
    for kind in DEVICE_KINDS:
        _ensure_device(organisation, kind, gateway=cobots[0])
    return DemoOrganisation(organisation, users, passwords, team, cobots)


def _ensure_member(
    organisation: Organisation, persona: Persona, keep_password: bool
) -> tuple[User, str | None]:
    existing = User.objects.filter(username=persona.username).first()
    password: str | None = None
    if existing is not None and keep_password and existing.has_usable_password():
        user = existing
    else:
        password = generate_password()
        user = organisation_services.provision_user(persona.username, password=password)
    membership = Membership.objects.filter(organisation=organisation, user=user).first()
    if membership is None:
        organisation_services.add_member(organisation, user, persona.role)
    elif membership.role != persona.role:
        organisation_services.change_role(membership, persona.role)
    return user, password


def _ensure_team(organisation: Organisation, operators: list[User]) -> Team:
    team = Team.objects.filter(organisation=organisation, name=TEAM_NAME).first()
    if team is None:
        team = organisation_services.create_team(organisation, name=TEAM_NAME)
    memberships = Membership.objects.filter(organisation=organisation, user__in=operators)
    return organisation_services.set_team_members(team, memberships)


def _ensure_cobot(organisation: Organisation, name: str, endpoint: str, source: str) -> Cobot:
    """The simulated cobot `name` at `endpoint`, where the demo starts its gateway."""
    settings = {"driver": DriverKind.SIMULATED, "endpoint": endpoint, "credentials_source": source}
    cobot = organisation.cobots.filter(name=name).first()
    if cobot is None:
        return cobot_services.create_cobot(organisation, name=name, **settings)
    changed = {
        field: value for field, value in {**settings, "is_active": True}.items()
        if getattr(cobot, field) != value
    }  # fmt: skip
    return cobot_services.update_cobot(cobot, **changed) if changed else cobot


def _ensure_device(organisation: Organisation, kind: str, *, gateway: Cobot) -> Device:
    """The floor's device of `kind` (the demo cobots stand on the floor, in no cell), named
    after its kind, on `gateway`'s simulator, which serves every kind under Devices/."""
    settings = {"kind": kind, "cell": "", "gateway": gateway, "is_active": True}
    device = organisation.devices.filter(name=kind).first()
    if device is None:
        return cobot_services.create_device(organisation, name=kind, **settings)
    changed = {field: value for field, value in settings.items() if getattr(device, field) != value}
    return cobot_services.update_device(device, **changed) if changed else device


def credential_lines(demo: DemoOrganisation) -> list[str]:
    """The personas' user names and passwords, a line each, to print once."""
    lines = ["Sign in with (the passwords are shown only now; run again for new ones):"]
    for persona in PERSONAS:
        password = demo.passwords[persona.username]
        shown = password if password is not None else "(unchanged)"
        lines.append(f"  {persona.username:<10} password {shown:<18} {Role(persona.role).label}")
    return lines
