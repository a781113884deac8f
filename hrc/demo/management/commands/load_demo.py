"""`manage.py load_demo`: the demo organisation with its personas, team, simulated cobots and the
example library (hrc.demo), and prints the personas' passwords.

Run it again at will: nothing is duplicated, an example whose file changed
is published as a new version, and every persona gets a new password
(printed once, here) unless --keep-passwords.
"""

from pathlib import Path
from typing import Any

from django.core.exceptions import ValidationError
from django.core.management.base import BaseCommand, CommandError, CommandParser

from hrc.database import ensure_migrated
from hrc.demo import library, organisation
from hrc.demo.library import EXAMPLES_DIR

__all__ = ["EXAMPLES_DIR", "Command"]


class Command(BaseCommand):
    help = (
        "Creates the 'Demo plant' organisation (an admin, an engineer, two operators in a team, "
        "two simulated cobots) and publishes the example patterns; prints new passwords. "
        "Safe to run again."
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
        parser.add_argument(
            "--cobot-endpoint",
            default="opc.tcp://127.0.0.1:{port}",
            metavar="TEMPLATE",
            help=(
                "Where each demo cobot's gateway is: {cobot} is its name, {COBOT} in upper case, "
                "{port} its demo port (default opc.tcp://127.0.0.1:{port}, as make demo serves "
                "them; docker/compose.yaml: opc.tcp://gateway-{cobot}:4840)."
            ),
        )
        parser.add_argument(
            "--cobot-credentials",
            default="none",
            metavar="TEMPLATE",
            help=(
                "Each demo cobot's credentials source, with the same fields (default none; "
                "docker/compose.yaml: env:{COBOT}_CREDENTIALS)."
            ),
        )
        parser.add_argument(
            "--keep-passwords",
            action="store_true",
            help="Leave the passwords of demo users who have one (they are not printed).",
        )

    def handle(self, *args: Any, **options: Any) -> None:
        endpoints = _filled(options["cobot_endpoint"], "--cobot-endpoint")
        credentials = _filled(options["cobot_credentials"], "--cobot-credentials")
        ensure_migrated()
        try:
            demo = organisation.provision(
                endpoints=endpoints,
                credentials=credentials,
                keep_passwords=options["keep_passwords"],
            )
        except ValidationError as error:
            raise CommandError(f"A demo cobot was refused: {'; '.join(error.messages)}") from None
        folder: Path = options["examples"]
        results = library.load_examples(
            demo.organisation, demo.users["engineer"], folder, demo.team, demo.cobots
        )
        if not results:
            self.stderr.write(f"No example patterns found in {folder}.")
        for loaded in results:
            if loaded.refused is None:
                self.stdout.write(f"  {loaded.file}: {loaded.outcome}")
            else:
                self.stderr.write(
                    self.style.WARNING(f"  {loaded.file}: not loaded: {loaded.refused}")
                )
        self.stdout.write(self.style.SUCCESS(f"{demo.organisation.name} is ready."))
        for line in organisation.credential_lines(demo):
            self.stdout.write(line)
        refused = [loaded.file for loaded in results if loaded.refused is not None]
        if refused and options["strict"]:
            raise CommandError(f"{len(refused)} example(s) could not be published: {refused}")


def _filled(template: str, option: str) -> dict[str, str]:
    """The template filled in for each demo cobot; CommandError naming the option when it cannot be."""
    try:
        return {cobot.name: cobot.endpoint(template) for cobot in organisation.DEMO_COBOTS}
    except (KeyError, IndexError, ValueError) as error:
        raise CommandError(
            f"{option} may use {{cobot}}, {{COBOT}} and {{port}} only, not {error}."
        ) from None
