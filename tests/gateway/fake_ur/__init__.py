"""A fake Universal Robots controller for the ur-rtde gateway backend's tests.

`FakeUR` runs a fake RTDE server on 127.0.0.1:30004 (ur-rtde always connects
to that port) and a fake dashboard server on a free port, both in front of
one FakeController, on an event loop in a thread of its own: the tests' loop
and the gateway's threads never wait for it. Its step program runs the frame
protocol of hrc_gateway/ur/hrc_step_program.script.

Only one process on the machine can listen on 30004, so `running_fake_ur`
holds an fcntl lock on /tmp/hrc-fake-ur.lock for the fake's lifetime:
pytest-xdist workers take turns.

Modules: wire.py (RTDE packets and types), controller.py (robot state and
the step program), rtde_server.py, dashboard_server.py.
"""

from __future__ import annotations

import asyncio
import contextlib
import fcntl
import threading
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import IO, TypeVar

from tests.gateway.fake_ur.controller import FakeController
from tests.gateway.fake_ur.dashboard_server import FakeDashboardServer
from tests.gateway.fake_ur.rtde_server import FakeRTDEServer
from tests.support.polling import until, until_async

HOST = "127.0.0.1"
RTDE_PORT = 30004
LOCK_FILE = Path("/tmp/hrc-fake-ur.lock")
TICK = 0.002  # the controller's 500 Hz cycle
NEVER_REACHED = "The fake UR never reached the expected state."

T = TypeVar("T")


class FakeUR:
    def __init__(self, controller: FakeController | None = None) -> None:
        self.controller = controller or FakeController()
        self.rtde = FakeRTDEServer(self.controller, HOST, RTDE_PORT)
        self.dashboard = FakeDashboardServer(self.controller, HOST)
        self._loop: asyncio.AbstractEventLoop | None = None
        self._stopping: asyncio.Event | None = None
        self._thread: threading.Thread | None = None
        self._started = threading.Event()
        self._error: BaseException | None = None

    @property
    def dashboard_port(self) -> int:
        return self.dashboard.port

    def start(self, timeout: float = 5.0) -> FakeUR:
        self._thread = threading.Thread(target=self._run, name="fake-ur", daemon=True)
        self._thread.start()
        if not self._started.wait(timeout):
            raise TimeoutError("The fake UR did not start.")
        if self._error is not None:
            raise RuntimeError(f"The fake UR could not start: {self._error}") from self._error
        return self

    def stop(self, timeout: float = 5.0) -> None:
        if self._loop is not None and self._stopping is not None:
            self._loop.call_soon_threadsafe(self._stopping.set)
        if self._thread is not None:
            self._thread.join(timeout)
            if self._thread.is_alive():
                raise TimeoutError("The fake UR did not stop.")

    def call(self, function: Callable[[], T], timeout: float = 5.0) -> T:
        """Runs `function` on the fake's loop (for its servers' state) and returns its result."""
        assert self._loop is not None

        async def run() -> T:
            return function()

        return asyncio.run_coroutine_threadsafe(run(), self._loop).result(timeout)

    def drop_rtde_connections(self) -> None:
        self.call(self.rtde.drop_connections)

    def drop_dashboard_connections(self) -> None:
        self.call(self.dashboard.drop_connections)

    def wait_until(self, condition: Callable[[FakeController], bool], timeout: float = 5.0) -> None:
        """Blocks until `condition(controller)` holds; for synchronous tests."""
        until(lambda: self._holds(condition), timeout, 0.005, NEVER_REACHED)

    async def until(
        self, condition: Callable[[FakeController], bool], timeout: float = 5.0
    ) -> None:
        """Waits until `condition(controller)` holds, letting the test's event loop run."""
        await until_async(lambda: self._holds(condition), timeout, 0.005, NEVER_REACHED)

    def _holds(self, condition: Callable[[FakeController], bool]) -> bool:
        with self.controller.lock:
            return condition(self.controller)

    def _run(self) -> None:
        try:
            asyncio.run(self._main())
        except BaseException as error:
            self._error = error
            self._started.set()

    async def _main(self) -> None:
        self._loop = asyncio.get_running_loop()
        self._stopping = asyncio.Event()
        await self.rtde.start()
        try:
            await self.dashboard.start()
            ticking = asyncio.create_task(self._tick())
            self._started.set()
            await self._stopping.wait()
            ticking.cancel()
            await self.dashboard.stop()
        finally:
            await self.rtde.stop()

    async def _tick(self) -> None:
        loop = asyncio.get_running_loop()
        last = loop.time()
        while True:
            await asyncio.sleep(TICK)
            now = loop.time()
            self.controller.tick(now - last)
            last = now


@contextlib.contextmanager
def machine_lock(timeout: float = 120.0) -> Iterator[None]:
    """Holds /tmp/hrc-fake-ur.lock: one fake UR (port 30004) per machine at a time."""
    with LOCK_FILE.open("a") as handle:
        until(
            lambda: _locked(handle), timeout, 0.05, f"{LOCK_FILE} stayed locked for {timeout:g} s."
        )
        try:
            yield
        finally:
            fcntl.flock(handle, fcntl.LOCK_UN)


def _locked(handle: IO[str]) -> bool:
    try:
        fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        return False
    return True


@contextlib.contextmanager
def running_fake_ur(controller: FakeController | None = None) -> Iterator[FakeUR]:
    with machine_lock():
        fake = FakeUR(controller).start()
        try:
            yield fake
        finally:
            fake.stop()
