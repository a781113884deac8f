"""manage.py live_cobots: watch every active cobot's gateway and broadcast its state to the tablets."""

import asyncio
import contextlib
from typing import Any

from django.core.management.base import BaseCommand, CommandParser

from hrc.database import ensure_migrated
from hrc.live.monitor import Monitor
from hrc.process import freeze_start_up


class Command(BaseCommand):
    help = (
        "Watches each active cobot's gateway (OPC UA subscription) and pushes its mode, safety "
        "mode, program, joints and display to the tablets. Run one beside the web server."
    )

    def add_arguments(self, parser: CommandParser) -> None:
        parser.add_argument("--organisation", type=int, help="Only this organisation's cobots.")
        parser.add_argument(
            "--interval", type=float, default=0.05,
            help="Seconds between two broadcasts of one cobot's state (default 0.05).",
        )  # fmt: skip

    def handle(self, *args: Any, **options: Any) -> None:
        if options["interval"] <= 0:
            self.stderr.write("--interval must be above 0 seconds.")
            raise SystemExit(2)
        ensure_migrated()
        monitor = Monitor(options["organisation"], options["interval"])
        self.stdout.write("live monitor watching cobots", ending="\n")
        self.stdout.flush()
        freeze_start_up()
        with contextlib.suppress(KeyboardInterrupt):
            asyncio.run(monitor.run())
