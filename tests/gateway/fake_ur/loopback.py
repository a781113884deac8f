"""What both fake controller servers share: a TCP server on loopback that can refuse and drop."""

from __future__ import annotations

import abc
import asyncio


class LoopbackServer(abc.ABC):
    """`start()` listens (port 0 picks one), `stop()` closes it and every connection."""

    def __init__(self, host: str, port: int) -> None:
        self.host = host
        self.port = port
        self.refuse = False  # close new connections at once (a controller not ready)
        self._server: asyncio.Server | None = None

    async def start(self) -> None:
        self._server = await asyncio.start_server(self._accept, self.host, self.port)
        self.port = self._server.sockets[0].getsockname()[1]

    async def stop(self) -> None:
        if self._server is not None:
            self._server.close()
        self.drop_connections()
        if self._server is not None:
            await self._server.wait_closed()

    @abc.abstractmethod
    def drop_connections(self) -> None:
        """Closes every connection, as a controller restart or a pulled cable would."""

    @abc.abstractmethod
    async def _accept(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None: ...
