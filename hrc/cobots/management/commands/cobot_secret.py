"""`python manage.py cobot_secret --organisation SLUG NAME --user U --password-env VAR [--cobot C ...]`

Sets an organisation's credentials secret from the deployment's environment,
once (a docker compose run, an Ansible task); cobots then use `secret:NAME`.
The password is read from the named variable, never from the command line,
where `ps` and shell histories would show it.
"""

from __future__ import annotations

import os
from typing import Any

from django.core.exceptions import ValidationError
from django.core.management.base import BaseCommand, CommandError, CommandParser

from hrc.cobots import services
from hrc.cobots.models import Cobot
from hrc.organisations.models import Organisation


class Command(BaseCommand):
    help = "Sets an organisation's cobot credentials secret from an environment variable."

    def add_arguments(self, parser: CommandParser) -> None:
        parser.add_argument("name", help="The secret's name; cobots use 'secret:NAME'.")
        parser.add_argument(
            "--organisation", required=True, help="The organisation's slug (or its id)."
        )
        parser.add_argument("--user", required=True, help="The gateway user name.")
        parser.add_argument(
            "--password-env",
            required=True,
            metavar="VAR",
            help="The environment variable holding the password.",
        )
        parser.add_argument(
            "--cobot",
            action="append",
            default=[],
            help="A cobot of the organisation to sign in with it from now on (repeat).",
        )

    def handle(self, *args: Any, **options: Any) -> None:
        organisation = _organisation(options["organisation"])
        password = os.environ.get(options["password_env"], "")
        if not password:
            raise CommandError(f"The environment variable {options['password_env']} is not set.")
        try:
            services.set_credentials_secret(
                organisation, options["name"], username=options["user"], password=password, by=None
            )
            for name in options["cobot"]:
                cobot = Cobot.objects.filter(organisation=organisation, name=name).first()
                if cobot is None:
                    raise CommandError(f"{organisation.name} has no cobot named {name}.")
                services.update_cobot(cobot, credentials_source=f"secret:{options['name']}")
        except ValidationError as error:
            raise CommandError(" ".join(error.messages)) from None
        used_by = f"; used by {', '.join(options['cobot'])}" if options["cobot"] else ""
        self.stdout.write(f"{organisation.name}: secret {options['name']} set{used_by}.")


def _organisation(reference: str) -> Organisation:
    found = Organisation.objects.filter(slug=reference).first()
    if found is None and reference.isascii() and reference.isdigit():
        found = Organisation.objects.filter(pk=int(reference)).first()
    if found is None:
        raise CommandError(f"No organisation has the slug or id {reference!r}.")
    return found
