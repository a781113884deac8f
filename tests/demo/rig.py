"""`manage.py demo` as a person runs it: a subprocess with its own database, ports and logs.

The demo test and the browser tests both drive it. It runs the project's
dev settings, as `make demo` does; the database is SQLite in a temporary
folder or a scratch PostgreSQL database, and Redis, when given, a private
redis-server, so nothing is shared with the test run or anyone else.
`make=True` runs `make demo DEMO_ARGS=…` from the project root as a newcomer
does, with no DATABASE_URL (None: the embedded SQLite under HRC_VAR_DIR) and
Ctrl-C going to the whole foreground process group, as at a terminal.
"""

from __future__ import annotations

import contextlib
import http.cookiejar
import json
import os
import re
import shlex
import signal
import subprocess
import sys
import time
import urllib.parse
import urllib.request
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any, Self
from urllib.parse import urlsplit, urlunsplit

from hrc.cobots.simulated import free_port
from hrc.demo.management.commands.demo import SERVING
from tests.support.paths import ROOT

PASSWORD_LINE = re.compile(r"^\s+(\S+)\s+password (\S+)\s", re.MULTILINE)
STARTED_LINE = re.compile(r"^\s+(.+): case (\d+)\s+http", re.MULTILINE)
START_TIMEOUT = 240.0


class DemoRun:
    def __init__(
        self,
        workdir: Path,
        *,
        database_url: str | None,
        redis_url: str | None = None,
        make: bool = False,
        arguments: Sequence[str] = (),
    ) -> None:
        self.workdir = workdir
        self.port = free_port()
        self.cobot_ports = {"cobot1": free_port(), "cobot2": free_port()}
        self.logs = workdir / "logs"
        self.out = workdir / "demo.out"
        self.make = make
        self.arguments = list(arguments)
        unset = ("DATABASE_URL", "REDIS_URL", "HRC_CELERY_QUEUE", "DJANGO_SETTINGS_MODULE")
        self.environment = {
            **{k: v for k, v in os.environ.items() if k not in unset},
            "HRC_VAR_DIR": str(workdir / "var"),
            "HRC_SIM_STATE_DIR": str(workdir / "cobots"),
            "HRC_PKI_DIR": str(workdir / "pki"),
            "PYTHONUNBUFFERED": "1",
        }
        if not make:  # manage.py's own default is the dev settings too; said here as before
            self.environment["DJANGO_SETTINGS_MODULE"] = "hrc.settings.dev"
        if database_url is not None:
            self.environment["DATABASE_URL"] = database_url
        if redis_url is not None:
            self.environment["REDIS_URL"] = redis_url
        self.process: subprocess.Popen[bytes] | None = None
        self.started_in: float | None = None

    @property
    def url(self) -> str:
        return f"http://127.0.0.1:{self.port}"

    def start(self, timeout: float = START_TIMEOUT) -> Self:
        """Starts the demo and returns once it prints the line that says it serves."""
        ports = ",".join(str(port) for port in self.cobot_ports.values())
        arguments = [
            "--port", str(self.port), "--cobot-ports", ports, "--time-scale", "0.05",
            "--logs", str(self.logs), *self.arguments,
        ]  # fmt: skip
        if self.make:
            command = ["make", "--no-print-directory", "demo", f"DEMO_ARGS={shlex.join(arguments)}"]
        else:
            command = [sys.executable, "manage.py", "demo", *arguments]
        began = time.monotonic()
        with self.out.open("wb") as out:
            # make runs in a session of its own: its group is what a terminal's Ctrl-C reaches.
            self.process = subprocess.Popen(
                command, cwd=ROOT, env=self.environment, stdout=out, stderr=subprocess.STDOUT,
                start_new_session=self.make,
            )  # fmt: skip
        deadline = began + timeout
        while SERVING not in self.output():
            if self.process.poll() is not None or time.monotonic() > deadline:
                self.stop()
                raise RuntimeError(f"The demo did not start:\n{self.output()}")
            time.sleep(0.2)
        self.started_in = time.monotonic() - began
        return self

    def output(self) -> str:
        return self.out.read_text(errors="replace") if self.out.exists() else ""

    def passwords(self) -> dict[str, str]:
        """User name → password, as the demo printed them."""
        return dict(PASSWORD_LINE.findall(self.output()))

    def token(self, username: str, password: str | None = None) -> str:
        """An API token for the person (their printed password unless another is given)."""
        secret = password if password is not None else self.passwords()[username]
        body = json.dumps({"username": username, "password": secret}).encode()
        request = urllib.request.Request(
            f"{self.url}/api/token/", data=body, headers={"Content-Type": "application/json"}
        )
        with urllib.request.urlopen(request, timeout=30) as response:
            return str(json.load(response)["token"])

    def get(self, token: str, path: str) -> dict[str, Any]:
        """The API's JSON answer at `path`, read with the token."""
        request = urllib.request.Request(
            f"{self.url}{path}", headers={"Authorization": f"Token {token}"}
        )
        with urllib.request.urlopen(request, timeout=30) as response:
            answer: dict[str, Any] = json.load(response)
            return answer

    def started_cases(self) -> dict[str, int]:
        """Pattern name → id of each case the banner says the demo started."""
        return {name: int(case) for name, case in STARTED_LINE.findall(self.output())}

    def descendants(self) -> dict[int, str]:
        """Every process below the demo's (pid → command line), from /proc."""
        assert self.process is not None
        parents: dict[int, int] = {}
        for entry in Path("/proc").iterdir():
            if entry.name.isdigit():
                with contextlib.suppress(OSError, ValueError, IndexError):
                    stat = (entry / "stat").read_text()
                    parents[int(entry.name)] = int(stat.rsplit(")", 1)[1].split()[1])
        found, frontier = {}, [self.process.pid]
        while frontier:
            parent = frontier.pop()
            for pid, ppid in parents.items():
                if ppid == parent and pid not in found:
                    found[pid] = _command_line(pid)
                    frontier.append(pid)
        return found

    def signal(self, signum: int, timeout: float = 60.0) -> int:
        """Sends `signum` to the demo's process only, or under make to make's whole group (as a
        terminal's Ctrl-C does); returns the exit code of the process started."""
        assert self.process is not None
        self._send(signum)
        return self.process.wait(timeout)

    def _send(self, signum: int) -> None:
        assert self.process is not None
        if self.make:
            os.killpg(self.process.pid, signum)
        else:
            self.process.send_signal(signum)

    def stop(self) -> None:
        """The clean-up of a test that failed half-way: SIGTERM, then SIGKILL."""
        if self.process is not None and self.process.poll() is None:
            with contextlib.suppress(ProcessLookupError):
                self._send(signal.SIGTERM)
            try:
                self.process.wait(60)
            except subprocess.TimeoutExpired:
                if self.make:
                    with contextlib.suppress(ProcessLookupError):
                        os.killpg(self.process.pid, signal.SIGKILL)
                self.process.kill()
                self.process.wait()


def alive(pid: int) -> bool:
    """True while the process exists and is not a zombie."""
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except (OSError, IndexError):
        return False
    return state != "Z"


def _command_line(pid: int) -> str:
    with contextlib.suppress(OSError):
        return Path(f"/proc/{pid}/cmdline").read_bytes().replace(b"\0", b" ").decode().strip()
    return ""


class Browserless:
    """A person's session without a browser: the sign-in form, cookies, pages."""

    def __init__(self, url: str) -> None:
        self.url = url
        self.cookies = http.cookiejar.CookieJar()
        self.opener = urllib.request.build_opener(urllib.request.HTTPCookieProcessor(self.cookies))

    def get(self, path: str) -> tuple[int, str, str]:
        """(status, final URL, body); 4xx and 5xx are answers too."""
        try:
            with self.opener.open(f"{self.url}{path}", timeout=30) as response:
                return response.status, response.url, response.read().decode()
        except urllib.error.HTTPError as error:
            return error.code, error.url, error.read().decode(errors="replace")

    def sign_in(self, username: str, password: str) -> bool:
        """Fills the sign-in form; True when the server took it and sent us on (operators to
        their tablet, the others to the start page) instead of back to the form."""
        self.get("/accounts/login/")
        token = next(c.value for c in self.cookies if c.name == "csrftoken")
        form = urllib.parse.urlencode(
            {"username": username, "password": password, "csrfmiddlewaretoken": token}
        ).encode()
        request = urllib.request.Request(
            f"{self.url}/accounts/login/", data=form, headers={"Referer": f"{self.url}/"}
        )
        with self.opener.open(request, timeout=30) as response:
            return bool(urlsplit(response.url).path != "/accounts/login/")

    def cookie_header(self) -> str:
        return "; ".join(f"{c.name}={c.value}" for c in self.cookies)


@contextlib.contextmanager
def scratch_postgres(name: str) -> Iterator[str]:
    """A new database on the test run's PostgreSQL server; dropped after, sessions and all."""
    import psycopg

    parts = urlsplit(os.environ["DATABASE_URL"])
    server = urlunsplit((parts.scheme, parts.netloc, "", "", ""))

    def admin(statement: str) -> None:
        with psycopg.connect(f"{server}/postgres", autocommit=True) as connection:
            connection.execute(statement)

    admin(f'DROP DATABASE IF EXISTS "{name}" WITH (FORCE)')
    admin(f'CREATE DATABASE "{name}"')
    try:
        yield f"{server}/{name}"
    finally:
        admin(f'DROP DATABASE IF EXISTS "{name}" WITH (FORCE)')
