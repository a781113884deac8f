"""A tablet without a browser: a real WebSocket client (websockets) with the store's rules in Python.

`Tablet.apply` follows frontend/src/live/store.ts; the event-stream test also
replays the captured events through the TypeScript store itself (replay.py).
"""

from __future__ import annotations

import asyncio
import json
import time
from typing import Any

from websockets.asyncio.client import ClientConnection, connect

from tests.live.server import LiveServer


async def open_socket(
    server: LiveServer, cookie: str | None, query: str = "", origin: str | None = None
) -> ClientConnection:
    headers = {"Origin": origin or server.url}
    if cookie:
        headers["Cookie"] = cookie
    return await connect(f"{server.ws_url}/ws/live/{query}", additional_headers=headers)


_pending: dict[int, list[dict[str, Any]]] = {}


async def receive(socket: ClientConnection, timeout: float = 10.0) -> dict[str, Any]:
    """The next event; a frame with several (one commit's) yields them one by one."""
    waiting = _pending.setdefault(id(socket), [])
    if not waiting:
        frame = json.loads(await asyncio.wait_for(socket.recv(), timeout))
        waiting.extend(frame if isinstance(frame, list) else [frame])
    return waiting.pop(0)


async def receive_until(
    socket: ClientConnection, condition: Any, timeout: float = 20.0, into: list[Any] | None = None
) -> dict[str, Any]:
    """Events until one satisfies `condition`; every one received goes to `into`."""
    deadline = time.monotonic() + timeout
    while True:
        remaining = deadline - time.monotonic()
        if remaining <= 0:
            raise AssertionError("no such event in time")
        event = await receive(socket, remaining)
        if into is not None:
            into.append(event)
        if condition(event):
            return event


async def db(function: Any, *args: Any, **kwargs: Any) -> Any:
    """Runs ORM code from an async test: in a thread of its own, its connection closed after."""
    from django.db import connections

    def run() -> Any:
        try:
            return function(*args, **kwargs)
        finally:
            connections.close_all()

    return await asyncio.to_thread(run)


def run(coroutine: Any) -> Any:
    """asyncio.run in a thread of its own: Playwright's sync API may hold this thread's loop
    (browser tests in the same process)."""
    import threading

    outcome: dict[str, Any] = {}

    def target() -> None:
        try:
            outcome["value"] = asyncio.run(coroutine)
        except BaseException as error:  # re-raised in the test's thread
            outcome["error"] = error

    thread = threading.Thread(target=target, name="live-test-scenario")
    thread.start()
    thread.join()
    if "error" in outcome:
        raise outcome["error"]
    return outcome.get("value")
