"""`python manage.py cobot_call cobot1 PowerOn` / `cobot_call cobot1 SelectProgram Coexistence_PickAndPlace`

Calls one of a cobot's URUA methods (PowerOn, PowerOff, SelectProgram,
StartProgram, PauseProgram, StopProgram, ...) with text arguments, then prints
the cobot's state.
"""

from __future__ import annotations

from typing import Any

from django.core.management.base import CommandParser

from hrc.cobots.drivers.base import DriverError
from hrc.cobots.management.commands._cobot_command import CobotCommand


class Command(CobotCommand):
    help = "Calls a URUA method on a cobot and prints its state."

    def add_arguments(self, parser: CommandParser) -> None:
        super().add_arguments(parser)
        parser.add_argument(
            "method", help="The method's path, e.g. PowerOn or RobotMode/ManualMode."
        )
        parser.add_argument("arguments", nargs="*", help="Text arguments, in order.")
        parser.add_argument("--timeout", type=float, default=60.0, help="Seconds to wait.")

    def handle(self, *args: Any, **options: Any) -> None:
        driver = self.driver(options)
        try:
            driver.call(options["method"], *options["arguments"], timeout=options["timeout"])
            state = driver.state()
        except DriverError as error:
            raise self.failure(error) from None
        self.stdout.write(self.style.SUCCESS(f"{driver.name}: {options['method']} done."))
        for key, value in state.items():
            self.stdout.write(f"  {key}: {value}")
