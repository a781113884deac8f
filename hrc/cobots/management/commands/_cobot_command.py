"""What the cobot commands share: finding the cobot and reporting driver errors."""

from __future__ import annotations

from typing import Any

from django.core.management.base import BaseCommand, CommandError, CommandParser

from hrc.cobots.drivers.base import DriverError
from hrc.cobots.drivers.runner import SyncDriver, driver_for, driver_for_cobot
from hrc.cobots.models import Cobot
from hrc.cobots.validators import validate_endpoint
from hrc.database import ensure_migrated


class CobotCommand(BaseCommand):
    """A command that talks to one cobot, named by its registration or reached by --endpoint."""

    def add_arguments(self, parser: CommandParser) -> None:
        parser.add_argument("cobot", help="The cobot's name (e.g. cobot1).")
        parser.add_argument(
            "--endpoint",
            help="Reach the gateway at this URL (insecure, loopback) instead of the registered cobot.",
        )
        parser.add_argument(
            "--organisation", help="The cobot's organisation, when several have one of that name."
        )
        parser.add_argument(
            "--connect-timeout", type=float, default=5.0, help="Seconds to reach the gateway."
        )

    def driver(self, options: dict[str, Any]) -> SyncDriver:
        name = options["cobot"]
        timeouts = {"connect_timeout": options["connect_timeout"]}
        if options["endpoint"]:
            try:
                validate_endpoint(options["endpoint"])
            except Exception as error:
                raise CommandError(
                    f"--endpoint: {' '.join(getattr(error, 'messages', [str(error)]))}"
                ) from None
            return driver_for(name, options["endpoint"], **timeouts)
        ensure_migrated()
        cobots = Cobot.objects.filter(name=name).select_related("organisation")
        if options["organisation"]:
            cobots = cobots.filter(organisation__name=options["organisation"])
        found = list(cobots[:2])
        if not found:
            raise CommandError(
                f"No registered cobot is named {name!r}; register it or pass --endpoint."
            )
        if len(found) > 1:
            raise CommandError(
                f"Several organisations have a cobot named {name!r}; pass --organisation."
            )
        if not found[0].is_active:
            raise CommandError(f"{name} is out of service (is_active is off).")
        return driver_for_cobot(found[0], **timeouts)

    def failure(self, error: DriverError) -> CommandError:
        advice = (
            "a retry may help" if error.transient else "a retry will not help until this is fixed"
        )
        return CommandError(f"{error} ({advice})")
