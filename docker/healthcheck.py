"""Health checks of the compose services (docker/compose.yaml): `python docker/healthcheck.py CHECK`.

Exits 0 when healthy, 1 with one line saying why not. Each check asks the
service for what it is there to do, as far as a check can:
- web [PORT]: the sign-in page answers 200 through daphne, as the proxy would ask;
- worker: this container's Celery worker (worker@<host name>) answers a ping over the broker;
- beat PIDFILE: the beat process named in its pid file is alive;
- monitor: every active cobot has a state the monitor reported within its TTL (15 s);
- gateway [PORT]: the gateway accepts a TCP connection on its OPC UA port.
"""

from __future__ import annotations

import os
import socket
import sys
import urllib.request
from collections.abc import Callable
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
WEB_PORT = 8000
GATEWAY_PORT = 4840


class Unhealthy(Exception):
    pass


def web(*arguments: str) -> None:
    # Daphne checks the Host header against ALLOWED_HOSTS: ask as the site's first host.
    host = os.environ.get("ALLOWED_HOSTS", "localhost").split(",")[0].strip().lstrip(".")
    request = urllib.request.Request(
        f"http://127.0.0.1:{int(arguments[0]) if arguments else WEB_PORT}/accounts/login/",
        headers={"Host": "localhost" if host in ("", "*") else host, "X-Forwarded-Proto": "https"},
    )
    with urllib.request.urlopen(request, timeout=5) as response:
        if response.status != 200:
            raise Unhealthy(f"the sign-in page answered {response.status}")


def worker(*_: str) -> None:
    _django()
    from hrc.celery import app

    node = f"worker@{socket.gethostname()}"
    if not app.control.ping([node], timeout=5):
        raise Unhealthy(f"{node} did not answer a ping within 5 s")


def beat(*arguments: str) -> None:
    if not arguments:
        raise Unhealthy("name beat's pid file (celery beat --pidfile)")
    try:
        pid = int(Path(arguments[0]).read_text().strip())
        os.kill(pid, 0)
    except (OSError, ValueError) as error:
        raise Unhealthy(f"no beat process ({arguments[0]}: {error})") from None


def monitor(*_: str) -> None:
    _django()
    from hrc.cobots.models import Cobot
    from hrc.live import cobot_states

    cobots = dict(Cobot.objects.filter(is_active=True).values_list("pk", "name"))
    reported = cobot_states.recall(list(cobots))
    silent = sorted(name for pk, name in cobots.items() if pk not in reported)
    if silent:
        raise Unhealthy(f"no recent state from {', '.join(silent)}")


def gateway(*arguments: str) -> None:
    port = int(arguments[0]) if arguments else GATEWAY_PORT
    try:
        socket.create_connection(("127.0.0.1", port), timeout=3).close()
    except OSError as error:
        raise Unhealthy(f"nothing accepts connections on port {port}: {error}") from None


def _django() -> None:
    sys.path.insert(0, str(ROOT))
    import django

    django.setup()


CHECKS: dict[str, Callable[..., None]] = {
    "web": web,
    "worker": worker,
    "beat": beat,
    "monitor": monitor,
    "gateway": gateway,
}


def main(argv: list[str]) -> int:
    if not argv or argv[0] not in CHECKS:
        print(f"usage: healthcheck.py {{{'|'.join(CHECKS)}}} [PORT or PIDFILE]", file=sys.stderr)
        return 2
    try:
        CHECKS[argv[0]](*argv[1:])
    except Exception as error:  # any failure is the answer "unhealthy", with its reason
        print(f"{argv[0]}: unhealthy: {error}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
