"""Without Redis (the embedded demo): what Celery beat and `live_cobots` do, inside the web server.

With no broker there is no beat to run the sweeper and no channel layer
another process could broadcast on (the in-memory layer lives in this
process, on the server's event loop). So the ASGI application is wrapped:
its first connection starts the sweeper thread and the cobot monitor, the
monitor as a task on the server's own loop, where the tablets' consumers
run. With Redis none of this is used: beat and `live_cobots` are processes.
"""

from __future__ import annotations

import asyncio
import logging
from typing import Any

from hrc.cases import dispatch
from hrc.live import groups
from hrc.live.monitor import Monitor

logger = logging.getLogger(__name__)

Scope = dict[str, Any]


class EmbeddedServices:
    """ASGI middleware that starts the embedded background services once, on the server's loop."""

    def __init__(self, application: Any) -> None:
        self.application = application
        self.monitor: asyncio.Task[None] | None = None

    async def __call__(self, scope: Scope, receive: Any, send: Any) -> Any:
        if self.monitor is None:
            self.monitor = start(asyncio.get_running_loop())
        return await self.application(scope, receive, send)


def start(loop: asyncio.AbstractEventLoop) -> asyncio.Task[None]:
    """Starts the sweeper (once per process) and the cobot monitor on `loop`; returns the monitor."""
    dispatch.start_embedded_sweeper()
    # Broadcasts from job threads reach the in-memory layer only through this loop.
    groups.serve_from(loop)
    task = loop.create_task(Monitor().run(), name="hrc-embedded-monitor")
    task.add_done_callback(_report_end)
    logger.info("Embedded sweeper and cobot monitor started")
    return task


def _report_end(task: asyncio.Task[None]) -> None:
    if not task.cancelled() and task.exception() is not None:
        logger.error("The embedded cobot monitor stopped", exc_info=task.exception())
