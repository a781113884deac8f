"""A real ASGI server (daphne's runserver, or daphne) on the test database, which a test may stop and start.

The browser fixtures keep one for the whole session; the live tests need
their own too: one on a private broker beside Celery workers, one that is
stopped under connected tablets and started again on the same port.
"""

from __future__ import annotations

import os
import subprocess
import sys
import time
import urllib.request
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Self

from django.conf import settings
from django.contrib.auth.models import User
from django.db import connection
from django.test import Client

from hrc.cobots.simulated import free_port


class _ManagePy:
    """A `manage.py` child process on the test database, its output in `log`."""

    def __init__(self, log: Path, environment: Mapping[str, str] | None = None) -> None:
        self.log = log
        self.environment = dict(environment or {})
        self.process: subprocess.Popen[bytes] | None = None

    def _spawn(
        self, *arguments: str, program: Sequence[str] = ("manage.py",)
    ) -> subprocess.Popen[bytes]:
        database = connection.settings_dict
        environment = {
            **os.environ,
            "DJANGO_SETTINGS_MODULE": "hrc.settings.test",
            "DATABASE_URL": f"postgres://{database['USER']}@{database['HOST']}:{database['PORT']}/{database['NAME']}",
            "DJANGO_ALLOW_ASYNC_UNSAFE": "",
            "PYTHONUNBUFFERED": "1",
            **self.environment,
        }
        with self.log.open("ab") as output:
            self.process = subprocess.Popen(
                [sys.executable, *program, *arguments],
                cwd=settings.BASE_DIR, env=environment, stdout=output, stderr=subprocess.STDOUT,
            )  # fmt: skip
        return self.process

    def stop(self) -> None:
        if self.process is not None and self.process.poll() is None:
            self.process.terminate()
            try:
                self.process.wait(10)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait(10)
        self.process = None


class LiveServer(_ManagePy):
    def __init__(self, log: Path, environment: Mapping[str, str] | None = None) -> None:
        super().__init__(log, environment)
        self.port = free_port()

    @property
    def url(self) -> str:
        return f"http://127.0.0.1:{self.port}"

    @property
    def ws_url(self) -> str:
        return f"ws://127.0.0.1:{self.port}"

    def start(self, timeout: float = 30.0, *, bare: bool = False) -> Self:
        """runserver, or with `bare` daphne itself as production runs it: no static files,
        and no migration check at start-up (which needs the database)."""
        if bare:
            arguments = ("-b", "127.0.0.1", "-p", str(self.port), "hrc.asgi:application")
            process = self._spawn(*arguments, program=("-m", "daphne"))
        else:
            process = self._spawn("runserver", "--noreload", "--insecure", f"127.0.0.1:{self.port}")
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if process.poll() is not None:
                raise RuntimeError(f"the test server exited; its log:\n{self.log.read_text()}")
            try:
                urllib.request.urlopen(f"{self.url}/accounts/login/", timeout=1).close()
                return self
            except OSError:
                time.sleep(0.1)
        self.stop()
        raise RuntimeError(f"the test server did not answer in time:\n{self.log.read_text()}")


def session_cookie(user: User) -> str:
    """A signed-in session for `user` in the database the server reads, as a Cookie header."""
    client = Client()
    client.force_login(user)
    return f"{settings.SESSION_COOKIE_NAME}={client.cookies[settings.SESSION_COOKIE_NAME].value}"


class MonitorProcess(_ManagePy):
    """`manage.py live_cobots` on the test database: the cobot panel's source."""

    def start(self, timeout: float = 30.0) -> Self:
        process = self._spawn("live_cobots")
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if process.poll() is not None:
                raise RuntimeError(f"the monitor exited; its log:\n{self.log.read_text()}")
            if "live monitor watching" in self.log.read_text():
                return self
            time.sleep(0.05)
        self.stop()
        raise RuntimeError(f"the monitor did not start:\n{self.log.read_text()}")
