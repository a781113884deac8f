"""Drivers for synchronous code: one event loop thread and one session per cobot per process.

Celery tasks and management commands are synchronous; the OPC UA driver is
asyncio. Each process gets one background loop holding its drivers, so a
worker keeps its sessions (and subscriptions) from task to task instead of
paying a connection per step. After a fork (Celery's prefork pool) the child
starts its own loop: sessions are never shared across processes.
"""

from __future__ import annotations

import asyncio
import os
import threading
from collections.abc import Callable, Coroutine, Mapping, Sequence
from typing import Any, TypeVar

from django.conf import settings

from hrc.cobots.credentials import CredentialsError, credentials_for
from hrc.cobots.drivers import readiness
from hrc.cobots.drivers.base import CobotUnreachable, DriverError, StepCommand, StepResult
from hrc.cobots.drivers.opcua.driver import ClientSecurity, OpcUaDriver
from hrc.cobots.models import Cobot

T = TypeVar("T")

# How long past a driver's own deadline the caller waits before giving up on
# the loop itself (which would mean the loop is stuck, a bug).
_GRACE = 5.0


class _Loop:
    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._pid: int | None = None
        self._loop: asyncio.AbstractEventLoop | None = None
        self.drivers: dict[tuple[str, str, ClientSecurity | None, str], OpcUaDriver] = {}

    def loop(self) -> asyncio.AbstractEventLoop:
        with self._lock:
            if self._pid != os.getpid() or self._loop is None:
                self._loop = asyncio.new_event_loop()
                self._pid = os.getpid()
                self.drivers = {}
                threading.Thread(
                    target=self._loop.run_forever, name="hrc-cobot-drivers", daemon=True
                ).start()
            return self._loop

    def run(self, coroutine: Coroutine[Any, Any, T], timeout: float) -> T:
        future = asyncio.run_coroutine_threadsafe(coroutine, self.loop())
        try:
            return future.result(timeout + _GRACE)
        except TimeoutError:
            future.cancel()
            raise CobotUnreachable("The cobot driver did not answer in time.") from None


_LOOP = _Loop()


class SyncDriver:
    """A blocking face on a process-wide OpcUaDriver; every call has a deadline."""

    def __init__(self, driver: OpcUaDriver) -> None:
        self.driver = driver

    @property
    def name(self) -> str:
        return self.driver.name

    def run_step(
        self,
        command: StepCommand,
        *,
        timeout: float | None = None,
        on_sent: Callable[[], None] | None = None,
    ) -> StepResult:
        limit = timeout or self.driver.step_timeout
        return _LOOP.run(self.driver.run_step(command, timeout=limit, on_sent=on_sent), limit)

    def call(self, method: str, *arguments: Any, timeout: float | None = None) -> list[Any]:
        limit = timeout or self.driver.step_timeout
        return _LOOP.run(self.driver.call(method, *arguments, timeout=limit), limit)

    def state(self, *, fresh: bool = True) -> dict[str, Any]:
        return _LOOP.run(self.driver.state(fresh=fresh), self.driver.connect_timeout)

    def read(self, path: str) -> Any:
        return _LOOP.run(self.driver.read(path), self.driver.connect_timeout)

    def read_many(self, paths: Sequence[str]) -> dict[str, Any]:
        return _LOOP.run(self.driver.read_many(paths), self.driver.connect_timeout)

    def write(self, values: Mapping[str, Any]) -> None:
        _LOOP.run(self.driver.write(values), self.driver.connect_timeout)

    def close(self) -> None:
        _LOOP.run(self.driver.close(), self.driver.request_timeout)


def driver_for(
    name: str,
    endpoint: str,
    security: ClientSecurity | None = None,
    *,
    session: str = "",
    **options: Any,
) -> SyncDriver:
    """The process's driver for a cobot at an endpoint, created on first use.

    `options` (timeouts) apply when the driver is created; later calls get the same driver.
    Another `session` ("devices") is a driver of its own, on a connection of its own.
    It connects only within settings.HRC_COBOT_NETWORKS when that is set.
    """
    options.setdefault("networks", settings.HRC_COBOT_NETWORKS)
    key = (name, endpoint, security, session)
    loop = _LOOP.loop()
    driver = _LOOP.drivers.get(key)
    if driver is None:

        async def create() -> OpcUaDriver:
            # Created inside the loop: asyncio objects bind to it.
            return OpcUaDriver(name, endpoint, security=security, **options)

        driver = asyncio.run_coroutine_threadsafe(create(), loop).result(_GRACE)
        _LOOP.drivers[key] = driver
    return SyncDriver(driver)


def driver_for_cobot(cobot: Cobot, **options: Any) -> SyncDriver:
    """The driver for a registered cobot: its endpoint, and its credentials when it has any.

    A cobot without credentials is reached without security (the embedded
    demo's loopback gateways); one with credentials over Basic256Sha256
    SignAndEncrypt with the installation's certificates.
    """
    try:
        credentials = credentials_for(cobot.name, cobot.organisation_id, cobot.credentials_source)
    except CredentialsError as error:
        raise DriverError(str(error)) from None
    security = None
    if credentials is not None:
        username, password = credentials
        security = ClientSecurity(settings.HRC_PKI_DIR, username, password)
    return driver_for(
        cobot.name, cobot.endpoint, security, page=readiness.page_of(cobot.pk), **options
    )
