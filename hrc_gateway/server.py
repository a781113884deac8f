"""One OPC UA server per cobot: URUA's address space in front of a Backend.

What URUA got wrong and this server does not (prototype-artefacts §1, §6):
- a failed command answers with a bad status code, and State/LastError says
  what failed and what to do;
- a write to a register the robot cannot receive is refused, not dropped, and
  a write request with one bad register applies none of them, so a handshake
  bit never rises over half-written step data;
- output registers are mirrored, and every value is pushed on change (no
  10 Hz loop), so subscribers see the handshake within a millisecond;
- it runs secured (Basic256Sha256 SignAndEncrypt, user names) unless started
  insecure, which it allows on loopback only.
"""

from __future__ import annotations

import asyncio
import logging
from collections.abc import Awaitable, Callable, Sequence
from typing import Any

from asyncua import Server, ua

from hrc_gateway import urua
from hrc_gateway.address_space import AddressSpace
from hrc_gateway.backend import (
    Backend,
    CommandFailed,
    MethodHandler,
    RegisterValue,
    Value,
)
from hrc_gateway.endpoints import EndpointError, bind_host, url_host
from hrc_gateway.pki import is_loopback

logger = logging.getLogger(__name__)

# Configures the server's security before it starts (hrc_gateway.pki.secure_server).
Secure = Callable[[Server], Awaitable[None]]

_NOT_SUPPORTED = "BadNotSupported"


class GatewayError(Exception):
    """The gateway cannot start as asked; the message says why."""


class Gateway:
    """An OPC UA server for the cobot `name`, backed by `backend`.

    `secure` configures certificates and users; None runs without security,
    which is refused unless `host` is a loopback address.
    """

    def __init__(
        self,
        name: str,
        backend: Backend,
        *,
        host: str = "127.0.0.1",
        port: int = 4841,
        secure: Secure | None = None,
    ) -> None:
        try:
            host = bind_host(host)
        except EndpointError as error:
            raise GatewayError(f"Cannot serve {name} on that host: {error}") from None
        if secure is None and not is_loopback(host):
            raise GatewayError(
                f"Refusing to serve {name} without security on {host}: --insecure is for "
                "loopback (127.0.0.1) only. Make certificates with "
                f"`python manage.py cobot_certificates {name}` instead."
            )
        self.name = name
        self.backend = backend
        self.host = host
        self.port = port
        self._secure = secure
        self.server = Server()
        self.space = AddressSpace(self.server, name)
        self._writes_to_pass_on: Callable[..., Awaitable[list[ua.StatusCode]]] | None = None
        self._heartbeat: asyncio.Task[None] | None = None
        # The method LastError names: only its own success clears it. Clients on two sessions
        # (a cobot's steps, its cell's device calls) call at once, and the one refused reads
        # LastError for why after its answer: another's success must not wipe it meanwhile.
        self._last_error_of = ""

    @property
    def endpoint(self) -> str:
        """The URL clients connect to; the real port once started with port 0."""
        port = self.server.bserver.port if self.server.bserver else self.port
        return f"opc.tcp://{url_host(self.host)}:{port}"

    async def start(self) -> None:
        """Builds the address space, starts the backend, then serves clients."""
        await self.server.init()
        self.server.set_endpoint(f"opc.tcp://{url_host(self.host)}:{self.port}")
        self.server.set_server_name(f"hrc cobot gateway {self.name}")
        if self._secure is None:
            self.server.set_security_policy([ua.SecurityPolicyType.NoSecurity])
        else:
            await self._secure(self.server)
        namespace = await self.server.register_namespace(f"urn:hrc:cobots:{self.name}")
        if namespace != urua.NAMESPACE_INDEX:  # URUA clients hard-code ns=2
            raise GatewayError(f"The cobot namespace got index {namespace}, not 2")
        await self.space.build()
        await self._add_urua_methods()
        self._intercept_writes()
        await self.backend.start(_BackendSpace(self), self.space.publish)
        await self._add_programs()
        await self.space.publish(
            {
                "SerialNumber": await self.backend.serial_number(),
                "RobotModel": await self.backend.robot_model(),
            }
        )
        await self.server.start()
        self._heartbeat = asyncio.create_task(self._beat())
        logger.info("Cobot gateway %s serving %s", self.name, self.endpoint)

    async def stop(self) -> None:
        if self._heartbeat is not None:
            self._heartbeat.cancel()
        await self.backend.close()
        await self.server.stop()

    async def _beat(self) -> None:
        beats = 0
        while True:
            await asyncio.sleep(urua.HEARTBEAT_SECONDS)
            beats = (beats + 1) % urua.INT32_MAX
            await self.space.publish({urua.STATE_HEARTBEAT: beats})

    async def drop_connections(self) -> None:
        for transport in list(self.server.iserver.asyncio_transports):
            transport.close()

    # Methods -----------------------------------------------------------------

    async def _add_urua_methods(self) -> None:
        backend = self.backend
        methods: list[tuple[str, MethodHandler, Sequence[tuple[str, str]]]] = [
            ("SelectProgram", self._select_program, [("name", "String")]),
            ("StartProgram", self._start_program, []),
            ("StopProgram", _returning_nothing(backend.stop_program), []),
            ("PauseProgram", _returning_nothing(backend.pause), []),
            (
                "RunUrScript",
                _refuse("The gateway runs no raw URScript; load a program."),
                [("content", "String")],
            ),
            ("PowerOn", _returning_nothing(backend.power_on), []),
            # Not in URUA, whose PowerOn also released the brakes (as ours still does): the
            # second half on its own, for a robot powered on to Idle at the pendant.
            ("BrakeRelease", _returning_nothing(backend.brake_release), []),
            ("PowerOff", _returning_nothing(backend.power_off), []),
            (
                "RobotMode/AutomaticMode",
                _returning_nothing(backend.set_operational_mode, "AUTOMATIC"),
                [],
            ),
            (
                "RobotMode/ManualMode",
                _returning_nothing(backend.set_operational_mode, "MANUAL"),
                [],
            ),
            ("RobotMode/ClearMode", _returning_nothing(backend.set_operational_mode, None), []),
            ("Messaging/PopupMessage", _returning_nothing(backend.popup), [("message", "String")]),
            ("Messaging/ClosePopupMessage", _returning_nothing(backend.popup, None), []),
            ("Messaging/AddToLog", _returning_nothing(backend.add_to_log), [("message", "String")]),
            (
                "Messaging/CloseSafetyPopup",
                # The software is never the safety function: a person at the cell checks the
                # cause and closes safety popups at the teach pendant.
                _refuse(
                    "Safety popups are closed at the teach pendant by a person who has checked "
                    "the cell; the gateway never closes them.",
                    "BadUserAccessDenied",
                ),
                [],
            ),
            (
                "Programs/UploadProgram",
                _refuse(
                    "Programs are installed on the robot by the cell integrator, not uploaded."
                ),
                [("name", "String"), ("program", "String")],
            ),
            (
                "Programs/DownloadProgram",
                _refuse("Programs are not downloaded through the gateway."),
                [("name", "String")],
            ),
        ]
        for path, handler, inputs in methods:
            await self.space.add_method(path, self._wrap(path, handler, inputs), inputs)

    async def _add_programs(self) -> None:
        programs = await self.backend.programs()
        await self.space.publish({"Programs/Programs": programs})
        for program in programs:
            load = _returning_nothing(self.backend.load_program, program)
            await self.space.add_method(
                f"Programs/{program}/SelectProgram",
                self._wrap(f"Programs/{program}/SelectProgram", load, []),
            )
            await self.space.add_method(
                f"Programs/{program}/StartProgram",
                self._wrap(f"Programs/{program}/StartProgram", self._load_and_play(program), []),
            )
            await self.space.add_method(
                f"Programs/{program}/StartAsUrScript",
                self._wrap(
                    f"Programs/{program}/StartAsUrScript",
                    _refuse("The gateway runs no raw URScript."),
                    [],
                ),
            )

    async def _select_program(self, name: str) -> list[Value]:
        try:
            program = urua.program_base_name(name)
        except ValueError as exc:
            raise CommandFailed(str(exc), "BadInvalidArgument") from None
        await self.backend.load_program(program)
        return []

    async def _start_program(self) -> list[Value]:
        # URUA skipped StartProgram while playing; a repeated start is harmless.
        if self.space.value(urua.STATE_PROGRAM_STATE) != urua.PROGRAM_PLAYING:
            await self.backend.play()
        return []

    def _load_and_play(self, program: str) -> MethodHandler:
        async def load_and_play() -> list[Value]:
            await self.backend.load_program(program)
            await self.backend.play()
            return []

        return load_and_play

    def _wrap(
        self, what: str, handler: MethodHandler, inputs: Sequence[tuple[str, str]]
    ) -> Callable[..., Awaitable[Any]]:
        """An asyncua method callback: checks arguments, reports failures with a status code.

        asyncua turns any exception from a method into BadUnexpectedError, so
        failures are returned as status codes, with the message in LastError.
        """

        async def call(parent: ua.NodeId, *arguments: ua.Variant) -> Any:
            try:
                values = _argument_values(what, arguments, inputs)
                outputs = await handler(*values)
            except CommandFailed as failure:
                return await self._failed(what, str(failure), failure.status)
            except Exception:
                logger.exception("%s failed unexpectedly on %s", what, self.name)
                return await self._failed(
                    what, "The gateway failed unexpectedly; see its log.", "BadInternalError"
                )
            if self._last_error_of == what:
                self._last_error_of = ""
                await self.space.publish({urua.STATE_LAST_ERROR: ""})
            return [ua.Variant(v) for v in outputs]

        return call

    async def _failed(self, what: str, message: str, status: str) -> ua.StatusCode:
        logger.warning("%s on %s refused (%s): %s", what, self.name, status, message)
        self._last_error_of = what
        await self.space.publish({urua.STATE_LAST_ERROR: f"{what}: {message}"})
        return ua.StatusCode(getattr(ua.StatusCodes, status))

    # Writes ------------------------------------------------------------------

    def _intercept_writes(self) -> None:
        """Routes client writes to the cobot's nodes through the backend.

        asyncua would store a written value in the node itself; here the
        backend decides, and the node changes only when the backend publishes.
        """
        service = self.server.iserver.attribute_service
        self._writes_to_pass_on = service.write
        service.write = self._write

    async def _write(self, params: ua.WriteParameters, user: Any = None) -> list[ua.StatusCode]:
        results: list[ua.StatusCode | None] = [None] * len(params.NodesToWrite)
        registers: dict[str, RegisterValue] = {}
        register_items: list[int] = []
        foreign: list[int] = []
        refusal: tuple[str, str] | None = None
        for index, item in enumerate(params.NodesToWrite):
            if item.NodeId.NamespaceIndex != urua.NAMESPACE_INDEX:
                foreign.append(index)
                continue
            path = self.space.path_of(item.NodeId)
            value = item.Value.Value.Value if item.Value and item.Value.Value else None
            register = _input_register(path)
            if item.AttributeId != ua.AttributeIds.Value or path is None:
                results[index] = await self._write_refused(item, "BadNotWritable")
            elif register is not None:
                register_items.append(index)
                try:
                    registers[register] = urua.coerce_register_value(register, value)
                except urua.RegisterError as error:
                    results[index] = _status(error.status)
                    refusal = refusal or (str(error), error.status)
            else:
                results[index] = await self._write_variable(path, value)
        if register_items:
            await self._write_registers(registers, register_items, results, refusal)
        if foreign and self._writes_to_pass_on is not None:
            passed = ua.WriteParameters(NodesToWrite=[params.NodesToWrite[i] for i in foreign])
            for index, status in zip(
                foreign, await self._writes_to_pass_on(passed, user), strict=True
            ):
                results[index] = status
        return [status or ua.StatusCode() for status in results]

    async def _write_registers(
        self,
        registers: dict[str, RegisterValue],
        items: list[int],
        results: list[ua.StatusCode | None],
        refusal: tuple[str, str] | None,
    ) -> None:
        """Applies the request's register writes as one batch, or none of them.

        A register that fails its own check gets its own status and the others
        BadInvalidArgument; when the backend refuses the batch, every item gets
        the backend's status (BadNotSupported, BadInvalidState, ...).
        """
        collateral = "BadInvalidArgument"
        if refusal is None:
            try:
                await self.backend.write_inputs(registers)
            except CommandFailed as failure:
                refusal = (str(failure), failure.status)
                collateral = failure.status
        if refusal is None:
            return
        message, status = refusal
        await self._failed("Write", f"{message} Nothing in this write request was applied.", status)
        for index in items:
            if results[index] is None:
                results[index] = _status(collateral)

    async def _write_variable(self, path: str, value: Any) -> ua.StatusCode:
        variable = self.space.variables[path]
        if not variable.writable:
            hint = " (outputs are written by the robot program)" if "/Outputs/" in path else ""
            await self._failed("Write", f"{path} is read-only{hint}.", "BadNotWritable")
            return _status("BadNotWritable")
        try:
            if path == "State/Override":
                if isinstance(value, bool) or not isinstance(value, int | float):
                    raise CommandFailed(
                        "State/Override takes a Double (percent).", "BadTypeMismatch"
                    )
                await self.backend.set_speed_override(float(value))
            else:
                await self.backend.write_variable(path, value)
        except CommandFailed as failure:
            await self._failed("Write", str(failure), failure.status)
            return _status(failure.status)
        return ua.StatusCode()

    async def _write_refused(self, item: ua.WriteValue, status: str) -> ua.StatusCode:
        known = self.server.iserver.aspace.get(item.NodeId) is not None
        if not known:
            status = "BadNodeIdUnknown"
        await self._failed("Write", f"{item.NodeId.to_string()} cannot be written.", status)
        return _status(status)


class _BackendSpace:
    """The GatewaySpace a backend sees: extra nodes, wrapped like URUA's."""

    def __init__(self, gateway: Gateway) -> None:
        self._gateway = gateway

    async def add_variable(
        self, path: str, value: Value, *, writable: bool = False, vtype: str | None = None
    ) -> None:
        await self._gateway.space.add_variable(path, value, writable=writable, vtype=vtype)

    async def add_method(
        self,
        path: str,
        handler: MethodHandler,
        inputs: Sequence[tuple[str, str]] = (),
        outputs: Sequence[tuple[str, str]] = (),
    ) -> None:
        wrapped = self._gateway._wrap(path, handler, inputs)
        await self._gateway.space.add_method(path, wrapped, inputs, outputs)

    async def drop_connections(self) -> None:
        # Let the calling method answer first, then cut every connection.
        asyncio.get_running_loop().call_later(
            0.01, lambda: asyncio.ensure_future(self._gateway.drop_connections())
        )


def _input_register(path: str | None) -> str | None:
    if path is None or not path.startswith("Register/Inputs/"):
        return None
    return path.rsplit("/", 1)[-1]


def _status(name: str) -> ua.StatusCode:
    return ua.StatusCode(getattr(ua.StatusCodes, name))


def _argument_values(
    what: str, arguments: Sequence[ua.Variant], inputs: Sequence[tuple[str, str]]
) -> list[Any]:
    if len(arguments) != len(inputs):
        raise CommandFailed(
            f"takes {len(inputs)} argument(s) ({', '.join(n for n, _ in inputs) or 'none'}), "
            f"got {len(arguments)}.",
            "BadArgumentsMissing" if len(arguments) < len(inputs) else "BadTooManyArguments",
        )
    values = []
    for argument, (name, type_name) in zip(arguments, inputs, strict=True):
        expected = ua.VariantType[type_name.removesuffix("[]")]
        if argument.VariantType != expected and not _widens(argument.VariantType, expected):
            raise CommandFailed(
                f"argument {name} must be a {type_name}, not a {argument.VariantType.name}.",
                "BadTypeMismatch",
            )
        values.append(argument.Value)
    return values


_INTEGER_TYPES = frozenset(
    {
        ua.VariantType.Int16,
        ua.VariantType.Int32,
        ua.VariantType.Int64,
        ua.VariantType.UInt16,
        ua.VariantType.UInt32,
    }
)


def _widens(given: ua.VariantType, expected: ua.VariantType) -> bool:
    # Clients pick their own integer width (asyncua's default is Int64).
    return given in _INTEGER_TYPES and expected in _INTEGER_TYPES


def _returning_nothing(command: Callable[..., Awaitable[None]], *bound: Any) -> MethodHandler:
    async def call(*arguments: Any) -> list[Value]:
        await command(*bound, *arguments)
        return []

    return call


def _refuse(message: str, status: str = _NOT_SUPPORTED) -> MethodHandler:
    async def call(*arguments: Any) -> list[Value]:
        raise CommandFailed(message, status)

    return call
