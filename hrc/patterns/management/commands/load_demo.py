"""`manage.py load_demo`: a demo organisation with people, simulated cobots and the example library.

Idempotent: run it again and it changes nothing, except that demo passwords
are reset and an example whose file changed is published as a new version.
"""

import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from django.contrib.auth.models import User
from django.core.exceptions import ValidationError
from django.core.management.base import BaseCommand, CommandError, CommandParser
from django.db import transaction

from hrc.cobots import services as cobot_services
from hrc.cobots.choices import DriverKind
from hrc.engine import FormatError
from hrc.organisations import services as organisation_services
from hrc.organisations.choices import Role
from hrc.organisations.models import Membership, Organisation
from hrc.patterns import services as pattern_services
from hrc.patterns.models import PatternModel
from hrc.patterns.selectors import latest_version
from hrc.patterns.services import PublishRefused

EXAMPLES_DIR = Path(__file__).resolve().parents[2] / "examples"
ORGANISATION_NAME = "Demo plant"
ORGANISATION_SLUG = "demo-plant"


@dataclass(frozen=True)
class DemoUser:
    username: str
    role: Role
    staff: bool = False

    @property
    def password(self) -> str:
        return f"demo-{self.username}"


DEMO_USERS = (
    DemoUser("admin", Role.ADMIN, staff=True),
    DemoUser("engineer", Role.ENGINEER),
    DemoUser("operator", Role.OPERATOR),
)
# `make demo` starts a simulated gateway per cobot on these ports (hrc/cobots/gateway/).
DEMO_COBOTS = (
    ("cobot1", "opc.tcp://127.0.0.1:4841"),
    ("cobot2", "opc.tcp://127.0.0.1:4842"),
)


class Command(BaseCommand):
    help = (
        "Creates the 'Demo plant' organisation with an admin, an engineer and an operator, "
        "two simulated cobots, and the example patterns, each published. Safe to run again."
    )

    def add_arguments(self, parser: CommandParser) -> None:
        parser.add_argument(
            "--examples",
            type=Path,
            default=EXAMPLES_DIR,
            help="Folder of hrc-pattern/1 *.json files to load (default: the shipped library).",
        )
        parser.add_argument(
            "--strict", action="store_true", help="Fail when an example cannot be published."
        )

    def handle(self, *args: Any, **options: Any) -> None:
        with transaction.atomic():
            organisation = ensure_organisation()
            users = {user.username: ensure_member(organisation, user) for user in DEMO_USERS}
            for name, endpoint in DEMO_COBOTS:
                ensure_cobot(organisation, name, endpoint)
        refused = self.load_examples(organisation, users["engineer"], options["examples"])
        self.report_users()
        if refused and options["strict"]:
            raise CommandError(f"{len(refused)} example(s) could not be published: {refused}")

    def load_examples(self, organisation: Organisation, engineer: User, folder: Path) -> list[str]:
        """Loads and publishes every *.json in `folder`; returns the names of files refused."""
        files = sorted(folder.glob("*.json")) if folder.is_dir() else []
        if not files:
            self.stderr.write(f"No example patterns found in {folder}.")
        refused = []
        for path in files:
            try:
                outcome = ensure_published(organisation, engineer, path)
            except (OSError, ValueError, FormatError, ValidationError, PublishRefused) as exc:
                refused.append(path.name)
                self.stderr.write(self.style.WARNING(f"  {path.name}: not loaded: {_reason(exc)}"))
                continue
            self.stdout.write(f"  {path.name}: {outcome}")
        return refused

    def report_users(self) -> None:
        self.stdout.write(self.style.SUCCESS(f"{ORGANISATION_NAME} is ready. Sign in with:"))
        for user in DEMO_USERS:
            self.stdout.write(
                f"  {user.username:<10} password {user.password:<15} ({user.role.label})"
            )


def ensure_organisation() -> Organisation:
    existing = Organisation.objects.filter(slug=ORGANISATION_SLUG).first()
    return existing or organisation_services.create_organisation(
        name=ORGANISATION_NAME, slug=ORGANISATION_SLUG
    )


def ensure_member(organisation: Organisation, demo: DemoUser) -> User:
    """The demo user with its known password and its role in the demo organisation."""
    user = organisation_services.provision_user(
        demo.username, password=demo.password, is_staff=demo.staff, is_superuser=demo.staff
    )
    membership = Membership.objects.filter(organisation=organisation, user=user).first()
    if membership is None:
        organisation_services.add_member(organisation, user, demo.role)
    elif membership.role != demo.role:
        organisation_services.change_role(membership, demo.role)
    return user


def ensure_cobot(organisation: Organisation, name: str, endpoint: str) -> None:
    """Registers the simulated cobot unless a cobot of that name exists (it is then left as is)."""
    if not organisation.cobots.filter(name=name).exists():
        cobot_services.create_cobot(
            organisation, name=name, driver=DriverKind.SIMULATED, endpoint=endpoint
        )


@transaction.atomic
def ensure_published(organisation: Organisation, engineer: User, path: Path) -> str:
    """Makes the file's document the latest published version of the pattern of its name.

    Returns what was done. Raises OSError, ValueError (not JSON), FormatError, ValidationError
    or PublishRefused.
    """
    document = json.loads(path.read_text(encoding="utf-8"))
    name = document.get("name") if isinstance(document, dict) else None
    name = name if isinstance(name, str) and name.strip() else path.stem
    pattern = PatternModel.objects.filter(organisation=organisation, name=name).first()
    if pattern is None:
        pattern = pattern_services.create_pattern(
            organisation, name=name, created_by=engineer, draft=document
        )
    else:
        latest = latest_version(pattern)
        if latest is not None and latest.document == document:
            return f"{name!r} unchanged (version {latest.number})"
        pattern_services.update_pattern(pattern, draft=document)
    version = pattern_services.publish_pattern(pattern, published_by=engineer)
    return f"{name!r} published as version {version.number}"


def _reason(exc: Exception) -> str:
    if isinstance(exc, PublishRefused):
        messages = [error.get("message", "") for error in exc.report.get("errors", [])]
        return "the check failed: " + " ".join(messages)
    return str(exc)
