"""`python manage.py cobot_gateway --name cobot1 --port 4841 --backend sim|ur-rtde ...`

Serves one cobot over OPC UA until SIGINT/SIGTERM. Prints one line
"<name> gateway serving <endpoint>" once clients can connect, so scripts and
tests can wait for it.
"""

from __future__ import annotations

import asyncio
import signal
from pathlib import Path
from typing import Any

from django.conf import settings
from django.core.management.base import BaseCommand, CommandError, CommandParser

from hrc.cobots.endpoints import EndpointError, bind_host
from hrc.cobots.gateway.backend import Backend, CommandFailed
from hrc.cobots.gateway.server import Gateway, GatewayError
from hrc.cobots.pki import PkiError, check_cobot_name, is_loopback, secure_server
from hrc.process import freeze_start_up

BACKENDS = ("sim", "ur-rtde")


class Command(BaseCommand):
    help = "Serves one cobot over OPC UA with URUA's address space (simulated or a UR robot)."

    def add_arguments(self, parser: CommandParser) -> None:
        parser.add_argument(
            "--name", required=True, help="The cobot's name, the root of its nodes."
        )
        parser.add_argument("--port", type=int, default=4841, help="TCP port (0 picks a free one).")
        parser.add_argument(
            "--host", default="127.0.0.1", help="Address to bind (default loopback)."
        )
        parser.add_argument("--backend", choices=BACKENDS, default="sim")
        parser.add_argument("--robot", help="ur-rtde: the UR controller's host name or address.")
        parser.add_argument(
            "--program",
            action="append",
            default=[],
            help="ur-rtde: a program installed on the robot (repeat); the dashboard cannot list them.",
        )
        parser.add_argument(
            "--time-scale",
            type=float,
            default=1.0,
            help="sim: multiply every duration (0.05 = twenty times faster, 0 = instant).",
        )
        parser.add_argument("--seed", type=int, help="sim: seed for the simulated devices.")
        parser.add_argument(
            "--state-file",
            type=Path,
            help="sim: where the simulated controller keeps its state (default under HRC_SIM_STATE_DIR).",
        )
        parser.add_argument(
            "--pki", type=Path, help="Certificate directory (default settings.HRC_PKI_DIR)."
        )
        parser.add_argument(
            "--insecure",
            action="store_true",
            help="No security, anonymous clients; refused unless --host is a loopback address.",
        )

    def handle(self, *args: Any, **options: Any) -> None:
        name = options["name"]
        try:
            check_cobot_name(name)
        except PkiError as error:
            raise CommandError(str(error)) from None
        try:
            # An address is bound in its plain form: "::ffff:127.0.0.1" as 127.0.0.1, "[::1]" as ::1.
            options["host"] = bind_host(options["host"])
        except EndpointError as error:
            raise CommandError(f"--host: {error}") from None
        if options["insecure"] and not is_loopback(options["host"]):
            raise CommandError(
                f"--insecure serves {name} to anyone who can reach it, so it is allowed on "
                f"loopback only, not on {options['host']}. Make certificates with "
                f"`python manage.py cobot_certificates {name}` and drop --insecure."
            )
        if not 0 <= options["port"] <= 65535:
            raise CommandError(f"--port must be within 0..65535, not {options['port']}.")
        backend = _backend(name, options)
        pki_dir = options["pki"] or settings.HRC_PKI_DIR
        secure = None if options["insecure"] else _securer(pki_dir, name)
        try:
            gateway = Gateway(
                name, backend, host=options["host"], port=options["port"], secure=secure
            )
            asyncio.run(self._serve(gateway))
        except (GatewayError, PkiError, CommandFailed, OSError) as error:
            raise CommandError(f"{name} gateway: {error}") from None

    async def _serve(self, gateway: Gateway) -> None:
        stop = asyncio.Event()
        loop = asyncio.get_running_loop()
        for sig in (signal.SIGINT, signal.SIGTERM):
            loop.add_signal_handler(sig, stop.set)
        await gateway.start()
        freeze_start_up()
        try:
            self.stdout.write(f"{gateway.name} gateway serving {gateway.endpoint}")
            self.stdout.flush()
            await stop.wait()
        finally:
            await gateway.stop()


def _backend(name: str, options: dict[str, Any]) -> Backend:
    if options["backend"] == "sim":
        from hrc.cobots.gateway.sim.backend import SimBackend

        if options["time_scale"] < 0:
            raise CommandError(f"--time-scale must be 0 or more, not {options['time_scale']}.")
        state_file = options["state_file"] or settings.HRC_SIM_STATE_DIR / f"{name}.json"
        state_file.parent.mkdir(parents=True, exist_ok=True)
        return SimBackend(
            name, time_scale=options["time_scale"], state_file=state_file, seed=options["seed"]
        )
    if not options["robot"]:
        raise CommandError("--backend ur-rtde needs --robot HOST, the UR controller's address.")
    from hrc.cobots.gateway.ur.backend import URBackend

    return URBackend(name, robot_host=options["robot"], programs=options["program"])


def _securer(pki_dir: Path, name: str) -> Any:
    async def secure(server: Any) -> None:
        await secure_server(server, pki_dir, name)

    return secure
