"""`python manage.py cobot_gateway --name cobot1 --port 4841 --backend sim|ur-rtde ...`

The gateway's own command (`hrc-gateway`, hrc_gateway/cli.py) with the same
flags, its certificates and simulator states where this deployment's settings
keep them.
"""

from __future__ import annotations

from typing import Any

from django.conf import settings
from django.core.management.base import BaseCommand, CommandError, CommandParser

from hrc_gateway import cli


class Command(BaseCommand):
    help = "Serves one cobot over OPC UA with URUA's address space (simulated or a UR robot)."

    def add_arguments(self, parser: CommandParser) -> None:
        cli.add_arguments(parser)

    def handle(self, *args: Any, **options: Any) -> None:
        defaults = cli.Defaults(
            pki_dir=settings.HRC_PKI_DIR, sim_state_dir=settings.HRC_SIM_STATE_DIR
        )
        try:
            cli.serve(options, defaults, self._say)
        except cli.StartError as error:
            raise CommandError(str(error)) from None

    def _say(self, line: str) -> None:
        self.stdout.write(line)
        self.stdout.flush()
