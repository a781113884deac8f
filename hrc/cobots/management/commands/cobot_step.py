"""`python manage.py cobot_step cobot1 --step 2 --workspace 1 --pose X Y Z RX RY RZ`

Runs one step on a cobot through the driver and prints what happened. The
cobot is found by name among the registered cobots, or reached directly with
--endpoint. Every run carries a fencing token (printed); pass it back with
--fence to repeat a step safely: a step that already ran is not sent again.
"""

from __future__ import annotations

import time
from typing import Any

from django.core.management.base import CommandError, CommandParser

from hrc.cobots.drivers.base import DriverError, Fence, StepCommand
from hrc.cobots.management.commands._cobot_command import CobotCommand
from hrc_gateway import urua


class Command(CobotCommand):
    help = "Runs one step on a cobot (step number, workspace, poses) and prints the outcome."

    def add_arguments(self, parser: CommandParser) -> None:
        super().add_arguments(parser)
        parser.add_argument("--step", type=int, required=True, help="The step number (Int24).")
        parser.add_argument("--workspace", type=int, default=0, help="The workspace (Int25).")
        parser.add_argument(
            "--pose",
            nargs=6,
            type=float,
            action="append",
            default=[],
            metavar=("X", "Y", "Z", "RX", "RY", "RZ"),
            help="A pose in metres and radians (rotation vector); give it twice for two poses.",
        )
        parser.add_argument(
            "--fence",
            help="The step's token ID.ATTEMPT; repeat a printed one to retry without running twice.",
        )
        parser.add_argument(
            "--timeout",
            type=float,
            default=120.0,
            help="Seconds to wait for the step (default 120).",
        )

    def handle(self, *args: Any, **options: Any) -> None:
        if len(options["pose"]) > 2:
            raise CommandError("A step carries at most two poses (--pose given more than twice).")
        fence = _fence(options["fence"])
        try:
            command = StepCommand(
                step=options["step"],
                workspace=options["workspace"],
                poses=[value for pose in options["pose"] for value in pose],
                fence=fence,
            )
        except (ValueError, urua.RegisterError) as error:
            raise CommandError(str(error)) from None
        driver = self.driver(options)
        self.stdout.write(
            f"{driver.name}: sending step {command.step} (workspace {command.workspace}) "
            f"with token {fence}"
        )
        try:
            result = driver.run_step(command, timeout=options["timeout"])
        except DriverError as error:
            raise self.failure(error) from None
        verb = "sent" if result.sent else "not sent again (it had already run)"
        self.stdout.write(
            self.style.SUCCESS(
                f"{driver.name}: step {command.step} {verb}; outcome: {result.outcome}; "
                f"{result.seconds:.3f} s"
            )
        )


def _fence(given: str | None) -> Fence:
    if given is None:
        # Unique enough for a shell: tenths of a second, wrapped into Int32.
        return Fence(int(time.time() * 10) % urua.INT32_MAX, 1)
    step_id, _, attempt = given.partition(".")
    try:
        return Fence(int(step_id), int(attempt or 1))
    except ValueError as error:
        raise CommandError(f"--fence takes ID.ATTEMPT, e.g. 1234.1 ({error}).") from None
