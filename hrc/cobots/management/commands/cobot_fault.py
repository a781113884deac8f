"""`python manage.py cobot_fault cobot1 protective-stop|disconnect|hang-next-step|slow-steps|clear|unlock`

Injects a fault into a simulated cobot over OPC UA (its Simulator/ methods),
as a test engineer would at URSim. `unlock` stands for the person at the
teach pendant who clears a protective stop; nothing in hrc does it by itself.
"""

from __future__ import annotations

from typing import Any

from django.core.management.base import CommandParser

from hrc.cobots.drivers.base import DriverError
from hrc.cobots.management.commands._cobot_command import CobotCommand

FAULTS = ("protective-stop", "disconnect", "hang-next-step", "slow-steps")


class Command(CobotCommand):
    help = "Injects or clears a fault on a simulated cobot."

    def add_arguments(self, parser: CommandParser) -> None:
        super().add_arguments(parser)
        parser.add_argument("fault", choices=(*FAULTS, "clear", "unlock"))
        parser.add_argument("--argument", default="", help="slow-steps: the slow-down factor.")

    def handle(self, *args: Any, **options: Any) -> None:
        driver = self.driver(options)
        fault = options["fault"]
        try:
            if fault == "clear":
                driver.call("Simulator/ClearFault", timeout=10)
            elif fault == "unlock":
                driver.call("Simulator/UnlockProtectiveStop", timeout=10)
            else:
                driver.call("Simulator/InjectFault", fault, options["argument"], timeout=10)
        except DriverError as error:
            raise self.failure(error) from None
        self.stdout.write(self.style.SUCCESS(f"{driver.name}: {fault} done."))
