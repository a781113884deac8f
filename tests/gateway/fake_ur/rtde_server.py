"""A fake RTDE server (port 30004, protocol v2) in front of a FakeController.

What it keeps of the real one: per-connection recipes numbered from 1 in
setup order (ur-rtde's RTDEIOInterface relies on it), NOT_FOUND for unknown
fields, IN_USE for inputs another connection (or a fieldbus adapter, see
`external_owners`) owns, inputs released when their connection closes,
outputs streamed at the frequency each recipe asked for, starting only after
the reply to START (ur-rtde reads exactly one reply per request). It sends no
unsolicited text messages: ur-rtde would take one for the next reply.
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
import struct
from dataclasses import dataclass

from tests.gateway.fake_ur import wire
from tests.gateway.fake_ur.controller import FakeController
from tests.gateway.fake_ur.loopback import LoopbackServer

logger = logging.getLogger(__name__)


@dataclass
class Recipe:
    names: list[str]
    types: list[str]
    layout: struct.Struct
    frequency: float = 0.0


def _zero(kind: str) -> object:
    if kind.startswith("VECTOR"):
        return [0] * int(wire.FORMATS[kind][0])
    return False if kind == "BOOL" else 0


class FakeRTDEServer(LoopbackServer):
    def __init__(self, controller: FakeController, host: str, port: int) -> None:
        super().__init__(host, port)
        self.controller = controller
        # Input fields a fieldbus adapter (EtherNet/IP, PROFINET, MODBUS) owns: IN_USE to all.
        self.external_owners: set[str] = set()
        self.owners: dict[str, _Connection] = {}
        self.connections: set[_Connection] = set()
        self.accepted = 0

    def drop_connections(self) -> None:
        for connection in list(self.connections):
            connection.close()

    async def _accept(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        self.accepted += 1
        if self.refuse:
            writer.close()
            return
        connection = _Connection(self, reader, writer)
        self.connections.add(connection)
        try:
            await connection.serve()
        except (asyncio.IncompleteReadError, ConnectionError):
            pass  # the client went away
        finally:
            connection.close()
            self.connections.discard(connection)
            for name in [n for n, owner in self.owners.items() if owner is connection]:
                del self.owners[name]


class _Connection:
    def __init__(
        self, server: FakeRTDEServer, reader: asyncio.StreamReader, writer: asyncio.StreamWriter
    ) -> None:
        self.server = server
        self.reader = reader
        self.writer = writer
        self.inputs: dict[int, Recipe] = {}
        self.outputs: dict[int, Recipe] = {}
        self.next_id = 1
        self.streams: list[asyncio.Task[None]] = []

    def close(self) -> None:
        for task in self.streams:
            task.cancel()
        self.streams = []
        self.writer.close()

    async def serve(self) -> None:
        handlers = {
            wire.REQUEST_PROTOCOL_VERSION: self._version,
            wire.GET_URCONTROL_VERSION: self._controller_version,
            wire.CONTROL_PACKAGE_SETUP_OUTPUTS: self._setup_outputs,
            wire.CONTROL_PACKAGE_SETUP_INPUTS: self._setup_inputs,
            wire.CONTROL_PACKAGE_START: self._start,
            wire.CONTROL_PACKAGE_PAUSE: self._pause,
            wire.DATA_PACKAGE: self._data,
        }
        while True:
            kind, payload = await wire.read_packet(self.reader)
            handler = handlers.get(kind)
            if handler is not None:  # text messages from the client are ignored
                await handler(payload)

    async def _send(self, kind: int, payload: bytes) -> None:
        self.writer.write(wire.packet(kind, payload))
        await self.writer.drain()

    async def _version(self, payload: bytes) -> None:
        (version,) = struct.unpack(">H", payload)
        await self._send(wire.REQUEST_PROTOCOL_VERSION, bytes([version == 2]))

    async def _controller_version(self, payload: bytes) -> None:
        await self._send(
            wire.GET_URCONTROL_VERSION, struct.pack(">4I", *self.server.controller.version)
        )

    async def _setup_outputs(self, payload: bytes) -> None:
        (frequency,) = struct.unpack(">d", payload[:8])
        names = [n for n in payload[8:].decode().split(",") if n]
        types = [wire.output_type(n) or "NOT_FOUND" for n in names]
        await self._send(
            wire.CONTROL_PACKAGE_SETUP_OUTPUTS,
            self._register(self.outputs, names, types, frequency),
        )

    async def _setup_inputs(self, payload: bytes) -> None:
        names = [n for n in payload.decode().split(",") if n]
        server = self.server
        types = []
        for name in names:
            owner = server.owners.get(name)
            in_use = name in server.external_owners or (owner is not None and owner is not self)
            types.append("IN_USE" if in_use else wire.input_type(name) or "NOT_FOUND")
        reply = self._register(self.inputs, names, types, 0.0)
        if reply[0] != 0:
            server.owners.update(dict.fromkeys(names, self))
        await self._send(wire.CONTROL_PACKAGE_SETUP_INPUTS, reply)

    def _register(
        self, recipes: dict[int, Recipe], names: list[str], types: list[str], frequency: float
    ) -> bytes:
        """The setup reply: recipe id (0 when a field is refused) and the field types."""
        recipe_id = 0
        if not any(t in ("NOT_FOUND", "IN_USE") for t in types):
            recipe_id, self.next_id = self.next_id, self.next_id + 1
            recipes[recipe_id] = Recipe(names, types, wire.recipe_struct(types), frequency)
        return bytes([recipe_id]) + ",".join(types).encode()

    async def _start(self, payload: bytes) -> None:
        await self._send(wire.CONTROL_PACKAGE_START, b"\x01")
        if not self.streams:
            self.streams = [
                asyncio.create_task(self._stream(recipe_id, recipe))
                for recipe_id, recipe in self.outputs.items()
            ]

    async def _pause(self, payload: bytes) -> None:
        for task in self.streams:
            task.cancel()
        self.streams = []
        await self._send(wire.CONTROL_PACKAGE_PAUSE, b"\x01")

    async def _data(self, payload: bytes) -> None:
        recipe = self.inputs.get(payload[0])
        if recipe is None:
            return  # the real controller ignores packages of unknown recipes
        flat = recipe.layout.unpack(payload[1:])
        values = wire.unflatten(recipe.types, flat)
        self.server.controller.apply_inputs(dict(zip(recipe.names, values, strict=True)))

    async def _stream(self, recipe_id: int, recipe: Recipe) -> None:
        loop = asyncio.get_running_loop()
        period = 1.0 / recipe.frequency if recipe.frequency > 0 else 0.002
        controller = self.server.controller
        next_send = loop.time()
        with contextlib.suppress(ConnectionError):
            while True:
                with controller.lock:
                    values = [controller.output_value(n) for n in recipe.names]
                values = [
                    _zero(t) if v is None else v for v, t in zip(values, recipe.types, strict=True)
                ]
                data = recipe.layout.pack(*wire.flatten(recipe.types, values))
                await self._send(wire.DATA_PACKAGE, bytes([recipe_id]) + data)
                next_send += period
                await asyncio.sleep(max(0.0, next_send - loop.time()))
