"""The OPC UA driver: one long-lived session per cobot, the step handshake by subscription.

The handshake registers are watched through one subscription (publishing
interval 0 by default: the gateway pushes every change at once), never
polled. A session that has driven no step for QUIET_SECONDS listens to the
heartbeat alone (its other monitored items disabled), and to everything again,
reading the cobot once, before its next step: every worker has a session to
every cobot it ever drove, and each would otherwise be sent every change of
every step the others drive (bench/README.md, "Quiet sessions"). A step's data
and its handshake bit go out in one write request. The fencing token makes
every call safe to repeat: before sending, the driver looks at what the cobot
already holds —
- its output token is ours: the step ran; finish the handshake, send nothing;
- its input token is ours with the bit up: the step is in flight; wait for it;
- anything else: finish any stale handshake, check the cobot can move, send.
Every wait has a deadline, and a lost session is reopened (with back-off)
within it.
"""

from __future__ import annotations

import asyncio
import contextlib
import dataclasses
import logging
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from asyncua import Client, Node, ua
from asyncua.common.methods import to_variant
from asyncua.ua.ua_binary import struct_from_binary

from hrc.cobots.drivers import readiness
from hrc.cobots.drivers.base import (
    NO_FENCE,
    CobotBusy,
    CobotDriver,
    CobotNotReady,
    CobotPaused,
    CobotStopped,
    CobotUnreachable,
    CommandRefused,
    DriverError,
    DriverNotSetUp,
    InvalidCommand,
    StepCommand,
    StepResult,
    StepTimeout,
    unreachable_message,
)
from hrc_gateway import urua
from hrc_gateway.endpoints import EndpointError, IPNetwork, check_networks
from hrc_gateway.pki import PkiError, check_gateway_certificate, secure_client

logger = logging.getLogger(__name__)

# Program states a pause leaves behind; a resume (StartProgram) plays on from them.
PAUSED = frozenset({"Pausing", urua.PROGRAM_PAUSED})

SESSION_TIMEOUT_MS = 600_000

IN_BIT = urua.register_path("Inputs", urua.HANDSHAKE_BIT)
IN_FENCE = (
    urua.register_path("Inputs", urua.FENCE_STEP),
    urua.register_path("Inputs", urua.FENCE_ATTEMPT),
)
OUT_BIT = urua.register_path("Outputs", urua.HANDSHAKE_BIT)
OUT_FENCE = (
    urua.register_path("Outputs", urua.FENCE_STEP),
    urua.register_path("Outputs", urua.FENCE_ATTEMPT),
)
OUT_OUTCOME = urua.register_path("Outputs", urua.OUTCOME)
STATE_PATHS = (
    urua.STATE_ROBOT_MODE,
    urua.STATE_SAFETY_MODE,
    urua.STATE_PROGRAM_STATE,
    urua.STATE_CURRENT_PROGRAM,
    urua.STATE_LAST_ERROR,
)
# Everything the driver keeps a live copy of.
WATCHED = (IN_BIT, *IN_FENCE, OUT_BIT, *OUT_FENCE, OUT_OUTCOME, *STATE_PATHS, urua.STATE_HEARTBEAT)
# A gateway not heard from for this long (several heartbeats) is taken for dead.
SILENCE_SECONDS = 8 * urua.HEARTBEAT_SECONDS
# A session that drove no step for this long stops listening until its next step. Longer than
# the gap between a cobot's steps in a busy chain (a worker drives a cobot's queue for
# HRC_CHAIN_SECONDS), far shorter than the seconds an operator's task takes between two steps.
QUIET_SECONDS = 0.25

# Status codes that mean the request itself was wrong, not the cobot's state.
_INVALID = frozenset(
    {
        "BadNodeIdUnknown",
        "BadNodeIdInvalid",
        "BadTypeMismatch",
        "BadOutOfRange",
        "BadNotWritable",
        "BadNotSupported",
        "BadArgumentsMissing",
        "BadTooManyArguments",
        "BadInvalidArgument",
        "BadMethodInvalid",
        "BadNotFound",
    }
)
# Refusals asyncua makes before the gateway's code runs: no explanation in LastError.
_NOT_FROM_THE_GATEWAY = frozenset({"BadNodeIdUnknown", "BadNodeIdInvalid", "BadMethodInvalid"})
_CONNECTION_ERRORS = (OSError, ConnectionError, asyncio.TimeoutError, ua.UaError)


@dataclass(frozen=True)
class ClientSecurity:
    """How the driver proves itself to a secured gateway (see hrc_gateway.pki)."""

    pki_dir: Path
    username: str
    password: str


class _SessionLost(Exception):
    """The session died mid-command; reopen it and look again."""


class OpcUaDriver(CobotDriver):
    """Drives the cobot `name` served by the gateway at `endpoint`."""

    def __init__(
        self,
        name: str,
        endpoint: str,
        *,
        security: ClientSecurity | None = None,
        connect_timeout: float = 5.0,
        request_timeout: float = 4.0,
        step_timeout: float = 300.0,
        release_timeout: float = 10.0,
        publishing_interval: float = 0.0,
        backoff: tuple[float, float] = (0.05, 5.0),
        page: str = "",
        networks: Sequence[IPNetwork] = (),
    ) -> None:
        self.name = name
        # HRC_COBOT_NETWORKS: the endpoint is resolved and checked before every connection.
        self.networks = tuple(networks)
        # The cobot's page in hrc, named in what a person must do (readiness.not_ready).
        self.page = page
        self.endpoint = endpoint
        self.security = security
        self.connect_timeout = connect_timeout
        self.request_timeout = request_timeout
        self.step_timeout = step_timeout
        self.release_timeout = release_timeout
        self.publishing_interval = publishing_interval
        self._backoff_min, self._backoff_max = backoff
        self._delay = self._backoff_min
        self._next_attempt = 0.0
        self._client: Client | None = None
        self._alive = False
        self._nodes: dict[str, Node] = {}
        self._paths: dict[ua.NodeId, str] = {}
        self.cache: dict[str, Any] = {}
        self._changed = asyncio.Event()
        # The subscription's items but the heartbeat's (by the gateway's handles), and whether
        # they report: not from QUIET_SECONDS after the last step until the next one.
        self._subscription_id = 0
        self._step_items: list[int] = []
        self._listening = False
        self._quiet: asyncio.TimerHandle | None = None
        self._falling_quiet: asyncio.Task[None] | None = None
        self._step_lock = asyncio.Lock()
        self._discarding: asyncio.Task[None] | None = None
        self._heard_at = 0.0
        # Set by call(): its effect (a protective stop, a program started) may not
        # have reached the subscription yet, so the next step reads first.
        self._cache_behind = False
        self._session_lock = asyncio.Lock()
        # Why the last connection attempt failed, for errors raised while backing off.
        self.last_failure = unreachable_message(name)

    # Session -----------------------------------------------------------------

    async def connect(self, timeout: float | None = None) -> None:
        """Opens the session now (it is otherwise opened on first use)."""
        await self._ensure_session(self._deadline(timeout or self.connect_timeout))

    async def close(self) -> None:
        self._cancel_quiet()
        client, self._client, self._alive = self._client, None, False
        if client is not None:
            try:
                await asyncio.wait_for(client.disconnect(), self.request_timeout)
            except Exception:  # closing a dead session fails; nothing is lost
                logger.debug("Disconnecting from %s failed", self.endpoint, exc_info=True)
        self._wake()

    async def _ensure_session(self, deadline: float) -> None:
        async with self._session_lock:
            while not self._alive:
                now = time.monotonic()
                if now < self._next_attempt:
                    if self._next_attempt >= deadline:
                        raise CobotUnreachable(
                            f"{self.last_failure} (still backing off before the next attempt)"
                        )
                    await asyncio.sleep(self._next_attempt - now)
                try:
                    await self._open(deadline)
                    self._delay = self._backoff_min
                except (DriverError, _SessionLost) as error:
                    if isinstance(error, DriverError) and not error.transient:
                        raise
                    self.last_failure = str(error)
                    self._fail_attempt()
                    if time.monotonic() + self._delay >= deadline:
                        raise CobotUnreachable(str(error)) from None

    def _fail_attempt(self) -> None:
        self._next_attempt = time.monotonic() + self._delay
        self._delay = min(self._delay * 2, self._backoff_max)

    async def _open(self, deadline: float) -> None:
        """Opens a session; every failure before it is open reads the same (unreachable_message)."""
        await self.close()
        try:
            await check_networks(self.endpoint, self.networks)
        except EndpointError as error:
            logger.warning("Not connecting to cobot %s at %s: %s", self.name, self.endpoint, error)
            raise CommandRefused(
                f"{self.name}: not connected: its endpoint is outside the networks cobots may "
                "be on (HRC_COBOT_NETWORKS)."
            ) from None
        try:
            await self._connect(deadline)
        except (DriverError, _SessionLost) as error:
            if isinstance(error, DriverNotSetUp):
                raise
            logger.warning("Cannot reach cobot %s at %s: %s", self.name, self.endpoint, error)
            raise CobotUnreachable(unreachable_message(self.name)) from None

    async def _connect(self, deadline: float) -> None:
        client = Client(self.endpoint, timeout=self.request_timeout)
        # asyncua asks for an hour and warns when the server grants less; ours grants ten minutes,
        # and the session is kept alive by its subscription anyway.
        client.session_timeout = SESSION_TIMEOUT_MS
        client.name = client.description = f"hrc driver for {self.name}"
        if self.security is not None:
            try:
                await secure_client(
                    client,
                    self.security.pki_dir,
                    self.name,
                    self.security.username,
                    self.security.password,
                )
            except PkiError as error:
                # This installation's own files are missing: nothing learnt about the endpoint.
                raise DriverNotSetUp(str(error)) from None
        client.connection_lost_callback = self._on_connection_lost
        timeout = max(0.01, min(self.connect_timeout, deadline - time.monotonic()))
        try:
            await asyncio.wait_for(client.connect(), timeout)
        except ua.UaStatusCodeError as error:
            raise self._security_error(error) from None
        except _CONNECTION_ERRORS as error:
            await self._explain_silent_gateway(error)
            raise CobotUnreachable(
                f"{self.name}: cannot reach the gateway at {self.endpoint} ({_describe(error)})."
            ) from None
        self._client = client
        try:
            await self._watch(client)
        except BaseException:
            self._client = None
            await _quietly_disconnect(client)
            raise
        self._alive = True
        self._heard_at = time.monotonic()
        # The subscription's first values may still be on their way.
        self._cache_behind = True
        self._wake()

    async def _explain_silent_gateway(self, error: BaseException) -> None:
        """A secured gateway that never answers may hold another certificate than the pinned one.

        asyncua encrypts to the pinned certificate, so such a gateway cannot
        answer and the connect times out; ask its endpoints why, and make it a
        permanent error when the certificate differs.
        """
        if self.security is None or not isinstance(error, asyncio.TimeoutError):
            return
        try:
            await check_gateway_certificate(
                self.endpoint, self.security.pki_dir, self.name, timeout=self.request_timeout
            )
        except PkiError as mismatch:
            raise CommandRefused(f"{self.name}: {mismatch}") from None
        except Exception:  # the diagnosis failed too: the plain timeout stands
            logger.debug("Could not check %s's certificate", self.name, exc_info=True)

    def _security_error(self, error: ua.UaStatusCodeError) -> DriverError:
        name = _status_name(error)
        if name in ("BadUserAccessDenied", "BadIdentityTokenInvalid", "BadIdentityTokenRejected"):
            return CommandRefused(
                f"{self.name}: the gateway at {self.endpoint} refused the user name or password."
            )
        if name.startswith("BadSecurity") or name.startswith("BadCertificate"):
            return CommandRefused(
                f"{self.name}: the gateway at {self.endpoint} refused the secure channel ({name})."
            )
        return CobotUnreachable(f"{self.name}: the gateway at {self.endpoint} answered {name}.")

    async def _watch(self, client: Client) -> None:
        """Reads the watched nodes once, then subscribes to their changes."""
        self._nodes = {path: client.get_node(urua.node_id(self.name, path)) for path in WATCHED}
        self._paths = {node.nodeid: path for path, node in self._nodes.items()}
        try:
            results = await client.read_attributes(list(self._nodes.values()))
        except _CONNECTION_ERRORS as error:
            raise _SessionLost(_describe(error)) from None
        if any(r.StatusCode is not None and r.StatusCode.is_bad() for r in results):
            raise InvalidCommand(
                f"The gateway at {self.endpoint} serves no cobot named {self.name!r} "
                f"(no node {urua.node_id(self.name, urua.STATE_ROBOT_MODE)})."
            )
        self.cache = {
            path: r.Value.Value if r.Value else None
            for path, r in zip(self._nodes, results, strict=True)
        }
        parameters = ua.CreateSubscriptionParameters(
            RequestedPublishingInterval=self.publishing_interval,
            RequestedLifetimeCount=300,
            RequestedMaxKeepAliveCount=100,
            PublishingEnabled=True,
        )
        subscription = await client.create_subscription(parameters, _Handler(self))
        handles = await subscription.subscribe_data_change(
            list(self._nodes.values()), queuesize=16, sampling_interval=0
        )
        self._step_items = [
            handle
            for path, handle in zip(self._nodes, handles, strict=True)
            if path != urua.STATE_HEARTBEAT and isinstance(handle, int)
        ]
        self._subscription_id, self._listening = subscription.subscription_id, True

    def _cancel_quiet(self) -> None:
        if self._quiet is not None:
            self._quiet.cancel()
            self._quiet = None

    def _fall_quiet_later(self) -> None:
        self._cancel_quiet()
        self._quiet = asyncio.get_running_loop().call_later(QUIET_SECONDS, self._fall_quiet_now)

    def _fall_quiet_now(self) -> None:
        self._quiet = None
        self._falling_quiet = asyncio.get_running_loop().create_task(self._stop_listening())

    async def _stop_listening(self) -> None:
        """Disables every item but the heartbeat's until _listen. The heartbeat goes on: asyncua
        recreates a subscription that has published nothing for a second. The cache goes stale
        meanwhile, so a cheap state() reads again."""
        if self._step_lock.locked():
            return  # a step began meanwhile; it arms the timer again when it ends
        async with self._step_lock:
            if not (self._alive and self._listening):
                return
            self._listening, self._cache_behind = False, True
            try:
                await self._monitor(ua.MonitoringMode.Disabled)
            except _CONNECTION_ERRORS as error:  # the next step finds out and reconnects
                logger.debug("%s: could not stop listening: %s", self.name, _describe(error))

    async def _listen(self) -> None:
        """Enables the items again and reads every watched node, in one round trip: the gateway
        sends the changes from now on, the read what happened while quiet. Items the gateway
        no longer knows (asyncua recreated a stale subscription) mean a new session."""
        if self._client is None:
            raise _SessionLost("no session")
        try:
            statuses, _ = await asyncio.gather(
                self._monitor(ua.MonitoringMode.Reporting), self._refresh()
            )
        except _CONNECTION_ERRORS as error:
            raise self._lost(error) from None
        if not all(status.is_good() for status in statuses):
            self._mark_lost(ConnectionError("the gateway no longer knows the subscription"))
            raise _SessionLost("the gateway no longer knows the subscription")
        self._listening, self._heard_at = True, time.monotonic()

    async def _monitor(self, mode: ua.MonitoringMode) -> list[ua.StatusCode]:
        if self._client is None:
            raise ConnectionError("no session")
        parameters = ua.SetMonitoringModeParameters()
        parameters.SubscriptionId = self._subscription_id
        parameters.MonitoredItemIds = self._step_items
        parameters.MonitoringMode = mode
        statuses: list[ua.StatusCode] = await self._client.uaclient.set_monitoring_mode(parameters)
        return statuses

    async def _on_connection_lost(self, error: Exception) -> None:
        self._mark_lost(error)

    def _mark_lost(self, error: BaseException) -> None:
        """The session is dead, however that was noticed: wake the waiters, drop the client."""
        logger.info("Session with %s lost: %r", self.endpoint, error)
        self._alive = False
        self._wake()
        # Stop the dead client's own loops (publish, watchdog) in a task of its own:
        # this callback runs inside the client's supervisor, which disconnect() cancels.
        client = self._client
        if client is not None:
            self._client = None
            self._discarding = asyncio.get_running_loop().create_task(_quietly_disconnect(client))

    def _on_change(self, node: Node, value: Any) -> None:
        self._heard_at = time.monotonic()
        path = self._paths.get(node.nodeid)
        if path is not None:
            self.cache[path] = value
            self._wake()

    def _wake(self) -> None:
        self._changed.set()
        self._changed = asyncio.Event()

    def _lost(self, error: BaseException) -> _SessionLost:
        self._alive = False
        return _SessionLost(_describe(error))

    @staticmethod
    def _deadline(seconds: float) -> float:
        return time.monotonic() + seconds

    # Steps -------------------------------------------------------------------

    async def run_step(
        self,
        command: StepCommand,
        *,
        timeout: float | None = None,
        on_sent: Callable[[], None] | None = None,
    ) -> StepResult:
        started = time.monotonic()
        deadline = self._deadline(timeout or self.step_timeout)
        # Whether any pass sent the step: a session lost after sending leads to a
        # pass that finds the step done and sends nothing.
        sent: list[bool] = []
        self._cancel_quiet()
        async with self._step_lock:
            try:
                return await self._run_step(command, deadline, started, sent, on_sent)
            finally:
                self._fall_quiet_later()

    async def _run_step(
        self,
        command: StepCommand,
        deadline: float,
        started: float,
        sent: list[bool],
        on_sent: Callable[[], None] | None,
    ) -> StepResult:
        """run_step's passes, under the step lock: a session lost mid-step is reopened and
        the step looked at again until the deadline."""
        while True:
            try:
                result = await self._drive(command, deadline, started, sent, on_sent)
                return dataclasses.replace(result, sent=result.sent or bool(sent))
            except _SessionLost as lost:
                logger.info("%s: session lost during step %s (%s)", self.name, command.fence, lost)
                if time.monotonic() >= deadline:
                    raise StepTimeout(
                        f"{self.name}: lost the gateway during step {command.fence} and it did "
                        "not come back in time; the step is in doubt.",
                        state=self.cache,
                    ) from None

    async def _drive(
        self,
        command: StepCommand,
        deadline: float,
        started: float,
        sent_before: list[bool],
        on_sent: Callable[[], None] | None,
    ) -> StepResult:
        await self._ensure_session(deadline)
        if not self._listening:
            await self._listen()
        if self._cache_behind or not self._ready_and_idle():
            # Before deciding on anything unusual, one read request: the subscription
            # may not yet have brought the effect of a command this client has just
            # made (StartProgram, say).
            await self._refresh()
        fence = command.fence
        token = (fence.step_id, fence.attempt)
        fenced = fence != NO_FENCE
        in_flight = fenced and self.cache[IN_BIT] and self._token(IN_FENCE) == token
        sent = False
        if fenced and self._token(OUT_FENCE) == token:
            # It ran before (we crashed, or this is a redelivery): only finish the handshake.
            outcome = self._outcome()
            await self._release(deadline)
            return StepResult(fence, outcome, sent=False, seconds=time.monotonic() - started)
        if not in_flight:
            await self._finish_stale_handshake(fence, deadline)
            self._check_ready(fence)
            sent_before.append(True)  # before: a lost answer may hide a write that landed
            await self._send(command)
            sent = True
            if on_sent is not None:
                on_sent()
        await self._wait(
            lambda c: bool(c[OUT_BIT]) and (not fenced or self._token(OUT_FENCE) == token),
            deadline,
            f"the acknowledgement of step {command.step} ({fence})",
            watch_safety=fence,
        )
        outcome = self._outcome()
        await self._release(deadline)
        return StepResult(fence, outcome, sent=sent, seconds=time.monotonic() - started)

    def _ready_and_idle(self) -> bool:
        """Whether the cached state says: no handshake under way, the cobot can move."""
        return not self.cache[IN_BIT] and not self.cache[OUT_BIT] and self._unready(None) is None

    async def _refresh(self) -> None:
        if self._client is None:
            raise _SessionLost("no session")
        try:
            values = await self._client.read_values(list(self._nodes.values()))
        except _CONNECTION_ERRORS as error:
            raise self._lost(error) from None
        self.cache.update(zip(self._nodes, values, strict=True))
        self._cache_behind = False

    def _token(self, paths: tuple[str, str]) -> tuple[int, int]:
        return (int(self.cache[paths[0]] or 0), int(self.cache[paths[1]] or 0))

    def _outcome(self) -> str:
        code = int(self.cache[OUT_OUTCOME] or 0)
        return urua.OUTCOMES.get(code, f"outcome {code}")

    async def _finish_stale_handshake(self, fence: Any, deadline: float) -> None:
        """Completes a handshake a crashed client left behind, or reports the cobot busy."""
        if self.cache[IN_BIT] and not self.cache[OUT_BIT]:
            raise CobotBusy(
                f"{self.name} is still running step {self._token(IN_FENCE)[0]}."
                f"{self._token(IN_FENCE)[1]}; {fence} waits until it is acknowledged.",
                state=self.cache,
            )
        if self.cache[IN_BIT]:
            await self._write({IN_BIT: False})
        if self.cache[OUT_BIT] or self.cache[IN_BIT]:
            await self._wait(
                lambda c: not c[OUT_BIT],
                min(deadline, self._deadline(self.release_timeout)),
                "the end of the previous handshake",
            )

    def _check_ready(self, fence: Any) -> None:
        problem = self._unready(fence)
        if problem is not None:
            raise problem

    def _unready(self, fence: Any) -> DriverError | None:
        """Why the cached state says the cobot cannot take a step now; None when it can."""
        problem = readiness.not_ready(
            self.name, self._state_from_cache(), page=self.page, endpoint=self.endpoint
        )
        if problem is not None:
            # The same error, saying the step stayed here: a retry sends it with its token.
            return type(problem)(f"{problem} Step {fence} was not sent.", state=self.cache)
        program = self.cache[urua.STATE_PROGRAM_STATE]
        if program in PAUSED:
            return CobotPaused(
                f"{self.name}'s program is {program!r}; step {fence} was not sent and waits for "
                "the program to be resumed.",
                state=self.cache,
            )
        if program != urua.PROGRAM_PLAYING:
            return CobotNotReady(
                f"{self.name}'s program is {program!r}, not Playing: select and start the step "
                f"program first; step {fence} was not sent.",
                state=self.cache,
            )
        return None

    async def _send(self, command: StepCommand) -> None:
        """Step, workspace, poses, token and the handshake bit, in one write request."""
        poses = list(command.poses) + [0.0] * (len(urua.POSE_REGISTERS) - len(command.poses))
        values: dict[str, Any] = {
            urua.register_path("Inputs", urua.STEP): command.step,
            urua.register_path("Inputs", urua.WORKSPACE): command.workspace,
            **{
                urua.register_path("Inputs", n): v
                for n, v in zip(urua.POSE_REGISTERS, poses, strict=True)
            },
            IN_FENCE[0]: command.fence.step_id,
            IN_FENCE[1]: command.fence.attempt,
            # Last, so the program never sees the bit before the data.
            IN_BIT: True,
        }
        await self._write(values)

    async def _release(self, deadline: float) -> None:
        if self.cache[IN_BIT]:
            await self._write({IN_BIT: False})
        await self._wait(
            lambda c: not c[OUT_BIT],
            min(deadline, self._deadline(self.release_timeout)),
            "the cobot to lower its acknowledgement",
        )

    async def _wait(
        self,
        done: Callable[[dict[str, Any]], bool],
        deadline: float,
        what: str,
        *,
        watch_safety: Any = None,
    ) -> None:
        """Waits for `done(cache)`; reopens a lost session; raises at the deadline."""
        while True:
            if not self._alive:
                raise _SessionLost("the session closed")
            if done(self.cache):
                return
            if watch_safety is not None:
                self._check_still_moving(watch_safety)
            now = time.monotonic()
            if now - self._heard_at > SILENCE_SECONDS:
                # The TCP connection may look open, but the gateway has stopped talking.
                self._mark_lost(TimeoutError("the gateway fell silent"))
                raise _SessionLost("the gateway fell silent")
            remaining = deadline - now
            if remaining <= 0:
                raise StepTimeout(
                    f"{self.name}: no {what} within the time allowed; the cobot is "
                    f"{self._summary()}. The step is in doubt: retry it with the same token.",
                    state=self.cache,
                )
            changed = self._changed
            with contextlib.suppress(TimeoutError):
                await asyncio.wait_for(changed.wait(), min(remaining, SILENCE_SECONDS))

    def _check_still_moving(self, fence: Any) -> None:
        safety = self.cache[urua.STATE_SAFETY_MODE]
        if safety not in urua.SAFETY_MODES_THAT_MOVE:
            raise CobotStopped(
                f"{self.name} went into {safety} during step {fence}; the step is in doubt. "
                "A person must clear the stop at the cell before it is retried.",
                state=self.cache,
            )
        if self.cache[urua.STATE_PROGRAM_STATE] == urua.PROGRAM_STOPPED:
            raise CobotNotReady(
                f"{self.name}'s program stopped during step {fence}; the step is in doubt.",
                state=self.cache,
            )

    def _summary(self) -> str:
        return ", ".join(
            f"{path.rsplit('/', 1)[-1]}={self.cache.get(path)!r}" for path in STATE_PATHS[:3]
        )

    # Reads, writes, methods ------------------------------------------------------

    async def state(self, *, fresh: bool = True) -> dict[str, Any]:
        await self._ensure_session(self._deadline(self.connect_timeout))
        if not fresh and not self._cache_behind:
            return self._state_from_cache()
        try:
            await self._refresh()  # fresh, not what the subscription has brought so far
        except _SessionLost as lost:
            raise self._unreachable(lost) from None
        return self._state_from_cache()

    def _state_from_cache(self) -> dict[str, Any]:
        return {path.rsplit("/", 1)[-1]: self.cache[path] for path in STATE_PATHS}

    async def read(self, path: str) -> Any:
        """The value of the node at `path` under the cobot's root."""
        await self._ensure_session(self._deadline(self.connect_timeout))
        assert self._client is not None
        node = self._client.get_node(urua.node_id(self.name, path))
        try:
            return await node.read_value()
        except ua.UaStatusCodeError as error:
            raise self._refusal(f"Reading {path}", _status_name(error), path) from None
        except _CONNECTION_ERRORS as error:
            raise self._unreachable(error) from None

    async def read_many(self, paths: Sequence[str]) -> dict[str, Any]:
        """The values of the nodes at `paths` under the cobot's root, in one read request."""
        await self._ensure_session(self._deadline(self.connect_timeout))
        assert self._client is not None
        nodes = [self._client.get_node(urua.node_id(self.name, path)) for path in paths]
        try:
            results = await self._client.read_attributes(nodes)
        except _CONNECTION_ERRORS as error:
            raise self._unreachable(error) from None
        for path, result in zip(paths, results, strict=True):
            if not result.StatusCode.is_good():
                raise self._refusal(f"Reading {path}", result.StatusCode.name, path)
        return {
            path: result.Value.Value if result.Value is not None else None
            for path, result in zip(paths, results, strict=True)
        }

    async def write(self, values: Mapping[str, Any]) -> None:
        """Writes values by path in one request; register values are checked here first."""
        await self._ensure_session(self._deadline(self.connect_timeout))
        try:
            await self._write(values)
        except _SessionLost as lost:
            raise self._unreachable(lost) from None

    async def _write(self, values: Mapping[str, Any]) -> None:
        if self._client is None:
            raise _SessionLost("no session")
        variants = [_variant(path, value) for path, value in values.items()]
        nodes = [self._client.get_node(urua.node_id(self.name, path)) for path in values]
        try:
            statuses = await self._client.write_values(
                nodes, [ua.DataValue(v) for v in variants], raise_on_partial_error=False
            )
        except _CONNECTION_ERRORS as error:
            raise self._lost(error) from None
        bad = [(path, s) for path, s in zip(values, statuses, strict=True) if not s.is_good()]
        if bad:
            path, status = bad[0]
            raise await self._refused(f"Writing {path}", status.name, path, "Write")

    async def call(self, method: str, *arguments: Any, timeout: float | None = None) -> list[Any]:
        """Calls the URUA method at `method` ("PowerOn", "Programs/x/StartProgram", ...).

        Returns its output arguments as a list (empty when it has none).
        """
        await self._ensure_session(self._deadline(self.connect_timeout))
        assert self._client is not None
        parent_path = method.rpartition("/")[0]
        parent = self._client.get_node(urua.node_id(self.name, parent_path))
        if parent_path in ("Axes", "Tcp", "Register"):
            parent = self._client.get_node(f"ns={urua.NAMESPACE_INDEX};s={self.name}/{parent_path}")
        method_id = ua.NodeId.from_string(urua.node_id(self.name, method))
        self._cache_behind = True
        limit = timeout or self.step_timeout
        try:
            outputs = await asyncio.wait_for(
                self._call_method(parent.nodeid, method_id, arguments, limit), limit
            )
        except ua.UaStatusCodeError as error:
            raise await self._refused(method, _status_name(error), method, method) from None
        except TimeoutError:
            raise StepTimeout(f"{self.name}: {method} did not return in time.") from None
        except _CONNECTION_ERRORS as error:
            raise self._unreachable(error) from None
        return outputs

    async def _call_method(
        self, parent: ua.NodeId, method: ua.NodeId, arguments: Sequence[Any], timeout: float
    ) -> list[Any]:
        """call_method_full with the call's own timeout: the session's request timeout
        (request_timeout, a few seconds) would cut a long call short, a device's (a linear axis
        moving for seconds) that the gateway answers only once it is done."""
        assert self._client is not None
        protocol = self._client.uaclient.protocol
        if protocol is None:
            raise ConnectionError("The session's connection is closed.")
        to_call = ua.CallMethodRequest()
        to_call.ObjectId, to_call.MethodId = parent, method
        to_call.InputArguments = to_variant(*arguments)
        request = ua.CallRequest()
        request.Parameters.MethodsToCall = [to_call]
        # The protocol writes the timeout into the request's header too: the gateway waits as long.
        data = await protocol.send_request(request, timeout)
        response = struct_from_binary(ua.CallResponse, data)
        response.ResponseHeader.ServiceResult.check()
        [result] = response.Results
        result.StatusCode.check()
        return [variant.Value for variant in result.OutputArguments or []]

    async def _refused(self, what: str, status: str, path: str, source: str) -> DriverError:
        """The error for a bad status, with the gateway's own explanation when it gave one.

        The gateway puts "<source>: <why>" in State/LastError, `source` being the
        method's path or "Write"; an explanation for something else is not ours.
        """
        explanation = ""
        if self._client is not None and status not in _NOT_FROM_THE_GATEWAY:
            try:
                node = self._client.get_node(urua.node_id(self.name, urua.STATE_LAST_ERROR))
                explanation = str(await node.read_value() or "")
            except Exception:
                explanation = ""
        prefix = f"{source}: "
        explanation = explanation[len(prefix) :] if explanation.startswith(prefix) else ""
        return self._refusal(what, status, path, explanation)

    def _refusal(self, what: str, name: str, path: str, explanation: str = "") -> DriverError:
        if name in _NOT_FROM_THE_GATEWAY:
            explanation = explanation or f"{self.name} has no node {path!r}"
        message = f"{self.name}: {what} refused ({name})" + (
            f": {explanation}" if explanation else "."
        )
        if name in _INVALID:
            return InvalidCommand(message, state=self.cache)
        return CommandRefused(message, state=self.cache)

    def _unreachable(self, error: BaseException) -> CobotUnreachable:
        self._lost(error)
        logger.warning("Lost cobot %s at %s: %s", self.name, self.endpoint, _describe(error))
        return CobotUnreachable(f"{self.name}: lost the connection to the cobot.")


class _Handler:
    """asyncua's subscription callbacks, handed to the driver."""

    def __init__(self, driver: OpcUaDriver) -> None:
        self._driver = driver

    def datachange_notification(self, node: Node, value: Any, data: Any) -> None:
        self._driver._on_change(node, value)

    def status_change_notification(self, status: Any) -> None:
        # The server ended the subscription (shutdown, timeout): treat the session as lost.
        self._driver._mark_lost(ConnectionError(f"subscription ended: {status}"))


def _variant(path: str, value: Any) -> ua.Variant:
    """The Variant a value is written as; register values are checked against the register."""
    if path.startswith("Register/"):
        name = path.rsplit("/", 1)[-1]
        try:
            value = urua.coerce_register_value(name, value)
            kind = urua.register_kind(name)
        except urua.RegisterError as error:
            raise InvalidCommand(f"{path}: {error}") from None
        vtype = {"Bit": ua.VariantType.Boolean, "Int": ua.VariantType.Int32}.get(
            kind, ua.VariantType.Double
        )
        return ua.Variant(value, vtype)
    if isinstance(value, bool):
        return ua.Variant(value, ua.VariantType.Boolean)
    if isinstance(value, float):
        return ua.Variant(value, ua.VariantType.Double)
    if isinstance(value, int):
        return ua.Variant(value, ua.VariantType.Int32)
    return ua.Variant(value)


def _status_name(error: ua.UaStatusCodeError) -> str:
    code = getattr(error, "code", None)
    if code is None:
        return type(error).__name__
    return str(ua.StatusCode(code).name)


def _describe(error: BaseException) -> str:
    return str(error) or type(error).__name__


async def _quietly_disconnect(client: Client) -> None:
    try:
        await asyncio.wait_for(client.disconnect(), 1.0)
    except Exception:
        logger.debug("Disconnect after a failed open failed", exc_info=True)
