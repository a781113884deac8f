"""ur-rtde's DashboardClient (port 29999) on a thread of its own, with deadlines.

DashboardClient releases the GIL in its calls and gives up on a reply after
2.5 s, so a thread is enough (unlike RTDE, see rtde_worker.py). Calls are
serialised: the dashboard answers one line per command, in order. Any failure
drops the connection; the backend reconnects in the background.
"""

from __future__ import annotations

import asyncio
import concurrent.futures
import contextlib
import logging
from collections.abc import Callable
from typing import Any, TypeVar

import dashboard_client

logger = logging.getLogger(__name__)

T = TypeVar("T")

# DashboardClient's own reply deadline is 2.5 s; ours only catches a thread that hangs anyway.
_CALL_TIMEOUT = 5.0
_CONNECT_TIMEOUT_MS = 2000


class DashboardUnavailable(Exception):
    """The dashboard server could not be reached, or the connection dropped."""


class Dashboard:
    def __init__(self, host: str, port: int) -> None:
        self.host = host
        self.port = port
        self._client: Any = None
        self._executor: concurrent.futures.ThreadPoolExecutor | None = None
        self._lock = asyncio.Lock()
        self.connected = False

    @property
    def address(self) -> str:
        return f"{self.host}:{self.port}"

    async def connect(self) -> None:
        """Connects (DashboardClient reads the greeting); DashboardUnavailable otherwise."""
        async with self._lock:
            await self._drop()

            def connect() -> Any:
                client = dashboard_client.DashboardClient(self.host, self.port, False)
                client.connect(_CONNECT_TIMEOUT_MS)
                return client

            self._client = await self._run(connect, "connect")
            self.connected = True

    async def call(self, command: str) -> str:
        """Sends one command line and returns the reply line; DashboardUnavailable otherwise."""
        if "\n" in command or "\r" in command:
            # A line break would smuggle a second command onto the line protocol.
            raise ValueError("A dashboard command is one line.")
        async with self._lock:
            if not self.connected:
                raise DashboardUnavailable(f"There is no dashboard connection to {self.address}.")
            client = self._client

            def call() -> str:
                client.send(command + "\n")
                return str(client.receive()).strip()

            try:
                return await self._run(call, command)
            except DashboardUnavailable:
                await self._drop()
                raise

    async def close(self) -> None:
        async with self._lock:
            await self._drop()
        if self._executor is not None:
            self._executor.shutdown(wait=False)
            self._executor = None

    async def _run(self, function: Callable[[], T], what: str) -> T:
        if self._executor is None:
            self._executor = concurrent.futures.ThreadPoolExecutor(1, "ur-dashboard")
        future = asyncio.get_running_loop().run_in_executor(self._executor, function)
        try:
            return await asyncio.wait_for(future, _CALL_TIMEOUT)
        except TimeoutError:
            # The thread is stuck in C++: leave it behind with its client.
            self._executor.shutdown(wait=False)
            self._executor = None
            self._client = None
            self.connected = False
            raise DashboardUnavailable(
                f"The dashboard at {self.address} did not answer {what!r} within {_CALL_TIMEOUT:g} s."
            ) from None
        except RuntimeError as error:  # ur-rtde's errors, e.g. "End of file", "Connection refused"
            raise DashboardUnavailable(
                f"The dashboard at {self.address} failed on {what!r}: {error}."
            ) from None

    async def _drop(self) -> None:
        client, self._client = self._client, None
        self.connected = False
        if client is not None and self._executor is not None:
            with contextlib.suppress(Exception):
                await asyncio.wait_for(
                    asyncio.get_running_loop().run_in_executor(self._executor, client.disconnect),
                    _CALL_TIMEOUT,
                )
