"""`hrc-gateway --name cobot1 --port 4841 --backend sim|ur-rtde ...` (or `python -m hrc_gateway`).

Serves one cobot over OPC UA until SIGINT/SIGTERM. Prints one line
"<name> gateway serving <endpoint>" once clients can connect, so scripts and
tests can wait for it. `manage.py cobot_gateway` is this command with the web
application's settings as its defaults.
"""

from __future__ import annotations

import argparse
import asyncio
import functools
import gc
import importlib
import os
import signal
import sys
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from asyncua import Server

from hrc_gateway.backend import Backend, CommandFailed
from hrc_gateway.endpoints import EndpointError, bind_host
from hrc_gateway.pki import PkiError, check_cobot_name, is_loopback, secure_server
from hrc_gateway.server import Gateway, GatewayError, Secure

# A backend's module is loaded only when asked for: the UR one needs ur-rtde (the [ur] extra).
BACKENDS = {"sim": "hrc_gateway.sim.backend", "ur-rtde": "hrc_gateway.ur.backend"}


class StartError(Exception):
    """The gateway cannot start or stopped serving: a wrong flag, a missing certificate, a taken port."""


@dataclass(frozen=True)
class Defaults:
    """Where certificates and simulator states are when no flag says."""

    pki_dir: Path
    sim_state_dir: Path


def environment_defaults() -> Defaults:
    """The web application's variables (HRC_PKI_DIR, HRC_SIM_STATE_DIR, HRC_VAR_DIR), else ./var."""
    var_dir = Path(os.environ.get("HRC_VAR_DIR") or "var")
    return Defaults(
        pki_dir=Path(os.environ.get("HRC_PKI_DIR") or var_dir / "pki"),
        sim_state_dir=Path(os.environ.get("HRC_SIM_STATE_DIR") or var_dir / "cobots"),
    )


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """The gateway's flags, shared with `manage.py cobot_gateway`."""
    parser.add_argument("--name", required=True, help="The cobot's name, the root of its nodes.")
    parser.add_argument("--port", type=int, default=4841, help="TCP port (0 picks a free one).")
    parser.add_argument("--host", default="127.0.0.1", help="Address to bind (default loopback).")
    parser.add_argument("--backend", choices=tuple(BACKENDS), default="sim")
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
        "--pki", type=Path, help="Certificate directory (default HRC_PKI_DIR, else var/pki)."
    )
    parser.add_argument(
        "--insecure",
        action="store_true",
        help="No security, anonymous clients; refused unless --host is a loopback address.",
    )


def serve(options: Mapping[str, Any], defaults: Defaults, say: Callable[[str], None]) -> None:
    """Serves the cobot the parsed flags describe until SIGINT or SIGTERM; StartError says why not."""
    name = options["name"]
    try:
        check_cobot_name(name)
    except PkiError as error:
        raise StartError(str(error)) from None
    host = _bind_host(options["host"])
    if options["insecure"] and not is_loopback(host):
        raise StartError(
            f"--insecure serves {name} to anyone who can reach it, so it is allowed on "
            f"loopback only, not on {host}. Make certificates with "
            f"`python manage.py cobot_certificates {name}` and drop --insecure."
        )
    if not 0 <= options["port"] <= 65535:
        raise StartError(f"--port must be within 0..65535, not {options['port']}.")
    backend = _backend(name, options, defaults)
    secure = None if options["insecure"] else _securer(options["pki"] or defaults.pki_dir, name)
    try:
        gateway = Gateway(name, backend, host=host, port=options["port"], secure=secure)
        asyncio.run(_serve(gateway, say))
    except (GatewayError, PkiError, CommandFailed, OSError) as error:
        raise StartError(f"{name} gateway: {error}") from None


def main(argv: Sequence[str] | None = None) -> int:
    """The console script: flags from the command line, defaults from the environment."""
    parser = argparse.ArgumentParser(
        prog="hrc-gateway", description="Serves one cobot over OPC UA with URUA's address space."
    )
    add_arguments(parser)
    options = vars(parser.parse_args(argv))
    try:
        # Flushed: whoever started the gateway waits for the line that says it serves.
        serve(options, environment_defaults(), functools.partial(print, flush=True))
    except StartError as error:
        print(f"{parser.prog}: error: {error}", file=sys.stderr)
        return 1
    return 0


def _bind_host(host: str) -> str:
    # An address is bound in its plain form: "::ffff:127.0.0.1" as 127.0.0.1, "[::1]" as ::1.
    try:
        return bind_host(host)
    except EndpointError as error:
        raise StartError(f"--host: {error}") from None


async def _serve(gateway: Gateway, say: Callable[[str], None]) -> None:
    stop = asyncio.Event()
    loop = asyncio.get_running_loop()
    for sig in (signal.SIGINT, signal.SIGTERM):
        loop.add_signal_handler(sig, stop.set)
    await gateway.start()
    # What start-up loaded lives as long as the process: frozen, no collection walks it again.
    gc.collect()
    gc.freeze()
    try:
        say(f"{gateway.name} gateway serving {gateway.endpoint}")
        await stop.wait()
    finally:
        await gateway.stop()


def _backend(name: str, options: Mapping[str, Any], defaults: Defaults) -> Backend:
    if options["backend"] == "sim":
        return _simulated(name, options, defaults)
    if not options["robot"]:
        raise StartError("--backend ur-rtde needs --robot HOST, the UR controller's address.")
    try:
        module = importlib.import_module(BACKENDS["ur-rtde"])
    except ImportError as error:
        raise StartError(
            f"--backend ur-rtde needs ur-rtde: pip install 'hrc-gateway[ur]' ({error})."
        ) from None
    backend: Backend = module.URBackend(
        name, robot_host=options["robot"], programs=options["program"]
    )
    return backend


def _simulated(name: str, options: Mapping[str, Any], defaults: Defaults) -> Backend:
    if options["time_scale"] < 0:
        raise StartError(f"--time-scale must be 0 or more, not {options['time_scale']}.")
    state_file = options["state_file"] or defaults.sim_state_dir / f"{name}.json"
    state_file.parent.mkdir(parents=True, exist_ok=True)
    module = importlib.import_module(BACKENDS["sim"])
    backend: Backend = module.SimBackend(
        name, time_scale=options["time_scale"], state_file=state_file, seed=options["seed"]
    )
    return backend


def _securer(pki_dir: Path, name: str) -> Secure:
    async def secure(server: Server) -> None:
        await secure_server(server, pki_dir, name)

    return secure
