"""The case runtime bench's rig: what its measurements share (bench/runtime.py runs them).

A scratch PostgreSQL database, a private redis-server, real Celery workers,
simulated OPC UA gateways at time scale 0, the API served over HTTP by
daphne, an OPC UA observer, and the bare Celery app whose worker is the
dispatch floor. Nothing at module level imports Django or hrc: the floor
worker imports this module.
"""

from __future__ import annotations

import asyncio
import contextlib
import http.client
import json
import os
import signal
import socket
import statistics
import subprocess
import sys
import tempfile
import threading
import time
import uuid
from collections.abc import Callable, Iterator, Mapping, Sequence
from concurrent.futures import Executor, Future
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Self
from urllib.parse import urlsplit, urlunsplit

from celery import Celery

from bench.handshake import percentile

if TYPE_CHECKING:  # Django's models load only after django.setup(), inside the functions
    from django.contrib.auth.models import User

    from hrc.cobots.models import Cobot
    from hrc.cobots.simulated import GatewayProcess
    from hrc.patterns.models import PatternVersion
    from tests.support.workers import RedisProcess, WorkerProcess

ROOT = Path(__file__).resolve().parent.parent
RESULTS_DIR = ROOT / "bench" / "results"
# Issue 21's targets, each a ratio to a floor measured in the same run: (a) request → register
# within 2× (p50) and 3× (p99) the floor sum with the ORM's commit; (b) with 2 workers at least
# half the cases per second the CPU floor allows; (c) a step in a long case within 1.25× of one
# in a short case.
TARGET_P50_TIMES, TARGET_P99_TIMES, TARGET_FLOOR = 2.0, 3.0, "floor_sum_orm"
TARGET_WORKERS, TARGET_SHARE_OF_CPU_BOUND = 2, 0.5
TARGET_FLAT_RATIO = 1.25
# Issue 4's absolute figures, still in the JSON for comparison with older results.
OLD_TARGET_P50_MS, OLD_TARGET_P99_MS, OLD_TARGET_CASES_PER_SECOND = 10.0, 50.0, 250.0
SETTINGS_MODULE = "hrc.settings.test"  # dev's DEBUG would keep every query in memory
DEFAULT_DATABASE_SERVER = "postgres://postgres@127.0.0.1:5432"
PROGRAM, STEP = "Coexistence_PickAndPlace", 3  # step 3, "pick": a 2 s wait, zero at time scale 0
FLOOR_REGISTER, FLOOR_VALUES_FROM = "Int29", 1_000_000  # an input no handshake writes
# An operator is never as quick as the bench: give the worker and the server the
# moment they need to finish with the last case (its broadcasts, its connection
# back to the pool) before the next step is timed.
SETTLE_SECONDS = 0.01

# The Celery floor: a bare app configured as hrc's (acks late, prefetch 1; its
# worker prefork, concurrency 1) whose one task hands back, through Redis, the
# wall-clock time its first line ran at. Its worker imports this module, which
# is why nothing at module level imports Django or hrc.
FLOOR_BROKER_ENV, FLOOR_QUEUE = "HRC_BENCH_FLOOR_BROKER", "bench-floor"
# Not the current app: hrc's shared tasks go through the current one, and a process that
# imports this module (the tests collect it) would send hrc's doorbells nowhere.
floor_app = Celery(
    "hrc-bench-floor",
    broker=os.environ.get(FLOOR_BROKER_ENV, "memory://"),
    set_as_current=False,
)
floor_app.conf.update(
    task_acks_late=True, worker_prefetch_multiplier=1, task_default_queue=FLOOR_QUEUE
)
_floor_redis: Any = None


# Celery ships no type hints (pyproject.toml says the same for hrc's tasks).
@floor_app.task(name="bench.runtime.note_start", ignore_result=True)  # type: ignore[untyped-decorator]
def note_start(key: str) -> None:
    """Pushes time.time() of the task's first line onto the list `key` of the broker's Redis."""
    started = time.time()
    global _floor_redis
    if _floor_redis is None:
        import redis

        _floor_redis = redis.Redis.from_url(os.environ[FLOOR_BROKER_ENV])
    _floor_redis.rpush(key, repr(started))


# The patterns and the settings ------------------------------------------------------------

SIGNAL_SHAPE = "p1 → to1 (operator) → p2 → tc1 (cobot: Coexistence_PickAndPlace step 3) → p3"
LOOP_SHAPE = (
    "p0 → begin → p1 → to1 (operator) → p2 → again [data.again] → p1 | done [not data.again] "
    "→ p3 → tc1 (cobot) → p4; the cases keep data.again true"
)


def _document(
    name: str, places: str, transitions: list[dict[str, Any]], arcs: str
) -> dict[str, Any]:
    """One process, operator o and cobot c; `arcs` as "a>b b>c …"."""
    first, *rest = places.split()
    process = {
        "id": "N",
        "workpiece": "w",
        "actors": ["c", "o"],
        "places": [{"id": first, "tokens": 1}, *({"id": p} for p in rest)],
        "transitions": transitions,
        "arcs": [arc.split(">") for arc in arcs.split()],
    }
    actors = [{"id": "c", "type": "cobot", "program": PROGRAM}, {"id": "o", "type": "operator"}]
    return {"format": "hrc-pattern/1", "name": name, "actors": actors, "processes": [process]}


def _tasks() -> list[dict[str, Any]]:
    step = {"step": {"program": PROGRAM, "number": STEP}}
    return [
        {"id": "to1", "performer": "o", "label": "place part"},
        {"id": "tc1", "performer": "c", "label": "pick", "task": step},
    ]


def signal_pattern() -> dict[str, Any]:
    """The smallest publishable pattern with one cobot task: every actor must perform a task,
    so an operator task comes first (SIGNAL_SHAPE)."""
    return _document("bench: operator, cobot", "p1 p2 p3", _tasks(), "p1>to1 to1>p2 p2>tc1 tc1>p3")


def loop_pattern() -> dict[str, Any]:
    """The operator task again and again while data.again holds (LOOP_SHAPE)."""
    silent = [
        {"id": "begin"},
        {"id": "again", "guard": "data.again"},
        {"id": "done", "guard": "not data.again"},
    ]
    arcs = "p0>begin begin>p1 p1>to1 to1>p2 p2>again again>p1 p2>done done>p3 p3>tc1 tc1>p4"
    return _document("bench: operator loop", "p0 p1 p2 p3 p4", _tasks() + silent, arcs)


@dataclass(frozen=True)
class Settings:
    steps: int = 500  # (a) timed steps
    warmup: int = 50  # (a) untimed steps first, and untimed floor samples
    floor_samples: int = 1000  # (a) timed samples of each floor
    cases: int = 1000  # (b) cases per row
    cobots: int = 4  # (b) simulated cobots, one job queue each
    workers: tuple[int, ...] = (1, 2)  # (b) one row per worker count
    repeats: int = 50  # (c) timed steps in each case length
    events: int = 1000  # (c) the long case's log
    quick: bool = False
    results_dir: Path = field(default=RESULTS_DIR, compare=False)


QUICK: dict[str, Any] = {
    "steps": 20,
    "warmup": 5,
    "floor_samples": 100,
    "cases": 40,
    "cobots": 2,
    "repeats": 10,
}


def summary(values_ms: Sequence[float]) -> dict[str, float]:
    ordered = list(values_ms)
    return {
        "n": len(ordered),
        **{
            f"{name}_ms": round(percentile(ordered, q), 3)
            for name, q in (("p50", 0.5), ("p99", 0.99))
        },
        "mean_ms": round(statistics.fmean(ordered), 3),
        "min_ms": round(min(ordered), 3),
        "max_ms": round(max(ordered), 3),
    }


# Statements per case --------------------------------------------------------------------------

# How Django logs transaction control (debug_transaction, savepoints): counted apart.
TRANSACTION_CONTROL = ("BEGIN", "COMMIT", "ROLLBACK", "SAVEPOINT", "RELEASE SAVEPOINT")


class StatementCounter(Executor):
    """Counts the SQL statements Django captures (CaptureQueriesContext), by phase.

    `phase(name)` counts a block's own statements. As the executor of
    hrc.cases.dispatch.run_inline it runs each task sent at once, in the
    calling thread, as a phase named by its dispatch.Task value; a task's own
    tasks run inside it and count as theirs, never twice. `counts` maps each
    phase to its statements, its transaction control (TRANSACTION_CONTROL)
    and how many times it ran. The task's name is found by looking for a
    registered task's function among the submitted call's closure
    (dispatch's private wrapper): should that change, the counts stay right
    and the phase is named UNNAMED_TASK.
    """

    UNNAMED_TASK = "a task of unknown name"

    def __init__(self) -> None:
        self.counts: dict[str, dict[str, int]] = {}
        self._lock = threading.Lock()
        self._frames = threading.local()

    @contextlib.contextmanager
    def phase(self, name: str) -> Iterator[None]:
        from django.db import connection
        from django.test.utils import CaptureQueriesContext

        stack: list[list[tuple[int, int]]] = self._frames.__dict__.setdefault("stack", [])
        if not stack:  # the log is a bounded deque: indices hold only while it is short
            connection.queries_log.clear()
        stack.append([])
        capture = CaptureQueriesContext(connection)
        try:
            with capture:
                yield
        finally:
            nested = stack.pop()
            span = (capture.initial_queries, capture.initial_queries + len(capture))
            if stack:
                stack[-1].append(span)
            self._note(name, connection.queries[span[0] : span[1]], span[0], nested)

    def _note(
        self, name: str, queries: list[dict[str, Any]], first: int, nested: list[tuple[int, int]]
    ) -> None:
        own = [
            query["sql"]
            for index, query in enumerate(queries, first)
            if not any(start <= index < end for start, end in nested)
        ]
        control = sum(1 for sql in own if sql.lstrip().upper().startswith(TRANSACTION_CONTROL))
        with self._lock:
            row = self.counts.setdefault(name, {"statements": 0, "transaction_control": 0, "runs": 0})  # fmt: skip
            row["statements"] += len(own) - control
            row["transaction_control"] += control
            row["runs"] += 1

    def submit(self, fn: Callable[..., Any], /, *args: Any, **kwargs: Any) -> Future[Any]:
        future: Future[Any] = Future()
        with self.phase(self.task_name(fn)):
            try:
                future.set_result(fn(*args, **kwargs))
            except BaseException as error:  # handed to the future, as a pool would
                future.set_exception(error)
        return future

    @classmethod
    def task_name(cls, call: Callable[..., Any]) -> str:
        """The dispatch.Task value of the task `call` runs, or UNNAMED_TASK."""
        from hrc.cases import dispatch

        captured = []
        for cell in getattr(call, "__closure__", None) or ():
            with contextlib.suppress(ValueError):  # an empty cell
                captured.append(cell.cell_contents)
        for task in dispatch.Task:
            with contextlib.suppress(KeyError):
                if any(value is dispatch.registered(task).run for value in captured):
                    return task.value
        return cls.UNNAMED_TASK


# The machinery: database, observer, HTTP, the floor worker ----------------------------------


def database_server() -> str:
    """DATABASE_URL's PostgreSQL server (without its database), or the local default."""
    parts = urlsplit(os.environ.get("DATABASE_URL", ""))
    if parts.scheme not in ("postgres", "postgresql") or not parts.netloc:
        return DEFAULT_DATABASE_SERVER
    return urlunsplit((parts.scheme, parts.netloc, "", "", ""))


@contextlib.contextmanager
def scratch_database(server: str) -> Iterator[str]:
    """Creates hrc_bench_<pid> on `server` and yields its URL; drops it, sessions and all."""
    import psycopg

    name = f"hrc_bench_{os.getpid()}"

    def admin(statement: str) -> None:
        with psycopg.connect(f"{server}/postgres", autocommit=True) as connection:
            connection.execute(statement)

    admin(f'DROP DATABASE IF EXISTS "{name}" WITH (FORCE)')
    admin(f'CREATE DATABASE "{name}"')
    try:
        yield f"{server}/{name}"
    finally:
        admin(f'DROP DATABASE IF EXISTS "{name}" WITH (FORCE)')


class Observer:
    """An OPC UA client of one gateway, on its own thread, noting when registers change.

    It subscribes as the driver does (publishing interval 0, sampling 0) and
    keeps the perf_counter() (and time.time(), to compare with rows) of the
    first notification of each (register, value): it sees a written input
    when and as the cobot's program would, an output when a client would.
    """

    def __init__(
        self, endpoint: str, cobot: str, registers: Sequence[str], direction: str = "Inputs"
    ) -> None:
        self.endpoint, self.cobot, self.registers = endpoint, cobot, tuple(registers)
        self.direction = direction
        self._loop = asyncio.new_event_loop()
        self._thread = threading.Thread(target=self._loop.run_forever, daemon=True)
        self._seen: dict[tuple[str, Any], float] = {}
        self._wall: dict[tuple[str, Any], float] = {}
        self._names: dict[Any, str] = {}
        self._changed = threading.Condition()
        self._client: Any = None

    def start(self) -> Self:
        self._thread.start()
        asyncio.run_coroutine_threadsafe(self._connect(), self._loop).result(30)
        return self

    async def _connect(self) -> None:
        from asyncua import Client, ua

        from hrc_gateway import urua

        self._client = Client(self.endpoint)
        await self._client.connect()
        nodes = [
            self._client.get_node(
                urua.node_id(self.cobot, urua.register_path(self.direction, name))
            )
            for name in self.registers
        ]
        self._names = {node.nodeid: name for node, name in zip(nodes, self.registers, strict=True)}
        # The heartbeat too: asyncua recreates a subscription quiet for a second,
        # and a notification could fall into the gap.
        nodes.append(self._client.get_node(urua.node_id(self.cobot, urua.STATE_HEARTBEAT)))
        parameters = ua.CreateSubscriptionParameters(
            RequestedPublishingInterval=0,
            RequestedLifetimeCount=300,
            RequestedMaxKeepAliveCount=100,
            PublishingEnabled=True,
        )
        subscription = await self._client.create_subscription(parameters, self)
        await subscription.subscribe_data_change(nodes, queuesize=16, sampling_interval=0)

    def datachange_notification(self, node: Any, value: Any, data: Any) -> None:
        now, wall = time.perf_counter(), time.time()
        register = self._names.get(node.nodeid)
        if register is not None:  # not the heartbeat
            with self._changed:
                self._seen.setdefault((register, value), now)
                self._wall.setdefault((register, value), wall)
                self._changed.notify_all()

    def status_change_notification(self, status: Any) -> None:
        pass  # the gateway went away: seen_at times out and says so

    def seen_at(self, register: str, value: int, timeout: float = 30.0) -> float:
        """perf_counter() when `register` first held `value`; TimeoutError when it never did."""
        with self._changed:
            if not self._changed.wait_for(lambda: (register, value) in self._seen, timeout):
                raise TimeoutError(f"{self.cobot}: {register} never became {value}")
            return self._seen[(register, value)]

    def wall_at(self, register: str, value: int, timeout: float = 30.0) -> float:
        """time.time() of the moment seen_at gives."""
        self.seen_at(register, value, timeout)
        return self._wall[(register, value)]

    def close(self) -> None:
        if self._client is not None:
            future = asyncio.run_coroutine_threadsafe(self._client.disconnect(), self._loop)
            with contextlib.suppress(Exception):
                future.result(10)
        self._loop.call_soon_threadsafe(self._loop.stop)
        self._thread.join(10)


class ApiServer:
    """The web process as production runs it (daphne, ASGI) on 127.0.0.1, and a JSON client;
    the live bench's server too (its tablets' WebSockets).

    A process of its own: served from a thread of the bench, the request
    would hold the GIL that the observer needs to note the register's
    change, and what is timed would include the bench's own waiting.
    """

    def __init__(self, workdir: Path, environment: Mapping[str, str]) -> None:
        from hrc.cobots.simulated import free_port

        self.port = free_port()
        self.log = workdir / "daphne.log"
        self._environment = {**os.environ, **environment, "PYTHONUNBUFFERED": "1"}
        self._process: subprocess.Popen[bytes] | None = None

    def start(self, timeout: float = 60.0) -> Self:
        command = [
            sys.executable, "-m", "daphne", "--verbosity", "0",
            "--bind", "127.0.0.1", "--port", str(self.port), "hrc.asgi:application",
        ]  # fmt: skip
        with self.log.open("ab") as output:
            self._process = subprocess.Popen(
                command, cwd=ROOT, env=self._environment, stdout=output, stderr=subprocess.STDOUT
            )
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if self._process.poll() is not None:
                raise RuntimeError(f"daphne exited:\n{self.log.read_text()[-4000:]}")
            with contextlib.suppress(OSError):
                socket.create_connection(("127.0.0.1", self.port), timeout=1).close()
                return self
            time.sleep(0.1)
        self.stop()
        raise RuntimeError(f"daphne did not listen within {timeout:.0f} s")

    def connect(self) -> http.client.HTTPConnection:
        """An open connection, so that a timed request does not pay for the TCP handshake."""
        connection = http.client.HTTPConnection("127.0.0.1", self.port, timeout=30)
        connection.connect()
        return connection

    def post(
        self, path: str, body: Mapping[str, Any], token: str = "", connection: Any = None
    ) -> tuple[int, Any]:
        return self.request("POST", path, body, token, connection)

    def request(
        self,
        method: str,
        path: str,
        body: Mapping[str, Any] | None = None,
        token: str = "",
        connection: Any = None,
    ) -> tuple[int, Any]:
        """The status and the JSON answer; `connection` (from `connect`) is used and closed."""
        connection = connection or self.connect()
        headers = {"Content-Type": "application/json"}
        if token:
            headers["Authorization"] = f"Token {token}"
        try:
            connection.request(method, path, None if body is None else json.dumps(body), headers)
            response = connection.getresponse()
            return response.status, json.loads(response.read() or b"null")
        finally:
            connection.close()

    def stop(self) -> None:
        if self._process is not None and self._process.poll() is None:
            self._process.terminate()
            try:
                self._process.wait(10)
            except subprocess.TimeoutExpired:
                self._process.kill()
                self._process.wait(10)


class FloorWorker:
    """`celery -A bench.runtime_rig:floor_app worker` with hrc's worker options, in its own group."""

    def __init__(self, workdir: Path, broker: str) -> None:
        self.broker, self.log = broker, workdir / "floor-worker.log"
        self.process: subprocess.Popen[bytes] | None = None

    def start(self, timeout: float = 60.0) -> Self:
        """Starts the worker; this process's `floor_app` sends to it from then on."""
        floor_app.conf.broker_url = self.broker
        command = [sys.executable, "-m", "celery", "-A", "bench.runtime_rig:floor_app", "worker",
                   "--hostname", "floor@%h", "--pool", "prefork", "--concurrency", "1",
                   "--loglevel", "INFO", "--without-gossip", "--without-mingle",
                   "--without-heartbeat", "--queues", FLOOR_QUEUE]  # fmt: skip
        with self.log.open("ab") as log:
            self.process = subprocess.Popen(
                command,
                cwd=ROOT,
                stdout=log,
                stderr=subprocess.STDOUT,
                env={**os.environ, FLOOR_BROKER_ENV: self.broker, "PYTHONUNBUFFERED": "1"},
                start_new_session=True,
            )
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline and self.process.poll() is None:
            # "ready." may come before its remote control listens (Redis fans control
            # messages out by PUBLISH: one sent earlier is lost): ready once it answers a ping.
            if " ready." in self.log.read_text(errors="replace") and floor_app.control.ping(
                destination=[self.node], timeout=0.5
            ):
                return self
            time.sleep(0.05)
        self.stop()
        raise RuntimeError(f"The floor worker did not start:\n{self.log.read_text()[-4000:]}")

    @property
    def node(self) -> str:
        """Its name for Celery's remote control."""
        return f"floor@{socket.gethostname()}"

    def pids(self) -> set[int]:
        from tests.support.workers import process_group  # not at module level: see the docstring

        return process_group(self.process.pid) if self.process is not None else set()

    def stop(self) -> None:
        if self.process is not None and self.process.poll() is None:
            os.killpg(self.process.pid, signal.SIGTERM)
            try:
                self.process.wait(20)
            except subprocess.TimeoutExpired:
                os.killpg(self.process.pid, signal.SIGKILL)
                self.process.wait(10)
        self.process = None


# The rig: everything the measurements share ---------------------------------------------------


@dataclass
class Rig:
    workdir: Path
    database_url: str
    redis: RedisProcess
    operator: User
    token: str
    signal: PatternVersion
    loop: PatternVersion
    cobots: list[Cobot]
    gateways: list[GatewayProcess]
    api: ApiServer
    workers: list[WorkerProcess] = field(default_factory=list)

    def use_workers(self, count: int) -> None:
        """Exactly `count` workers running; the first runs the beat that runs the sweeper."""
        from tests.support.workers import WorkerProcess

        while len(self.workers) > count:
            self.workers.pop().stop()
        environment = {
            "DJANGO_SETTINGS_MODULE": SETTINGS_MODULE,
            "DATABASE_URL": self.database_url,
            "REDIS_URL": self.redis.url,
            "HRC_SWEEP_SECONDS": "0.5",
            "HRC_RETRY_BACKOFF": "0.2",
        }
        while len(self.workers) < count:
            name, first = f"worker{len(self.workers)}", not self.workers
            worker = WorkerProcess(self.workdir, name=name, environment=environment, beat=first)
            self.workers.append(worker.start())

    def worker_nodes(self) -> list[str]:
        return [f"{worker.name}@{socket.gethostname()}" for worker in self.workers]


@contextlib.contextmanager
def rig(settings: Settings, progress: Callable[[str], None]) -> Iterator[Rig]:
    from tests.support.workers import RedisProcess

    with contextlib.ExitStack() as stack:
        workdir = Path(stack.enter_context(tempfile.TemporaryDirectory(prefix="hrc-bench-")))
        redis = RedisProcess(workdir).start()
        stack.callback(redis.stop)
        database_url = stack.enter_context(scratch_database(database_server()))
        progress(f"scratch database {database_url.rsplit('/', 1)[1]}, broker {redis.url}")
        _set_up_django(database_url, redis.url)
        stack.callback(_close_connections)
        gateways: list[GatewayProcess] = []
        stack.callback(_stop_all, gateways)
        made = _populate(workdir, settings.cobots, gateways)
        api = ApiServer(workdir, {
            "DJANGO_SETTINGS_MODULE": SETTINGS_MODULE, "DATABASE_URL": database_url,
            "REDIS_URL": redis.url,
        }).start()  # fmt: skip
        stack.callback(api.stop)
        status, body = api.post("/api/token/", made.pop("credentials"))
        if status != 200:
            raise RuntimeError(f"POST /api/token/ answered {status}: {body}")
        bench = Rig(
            workdir, database_url, redis, token=body["token"], api=api, gateways=gateways, **made
        )
        stack.callback(bench.use_workers, 0)
        yield bench


def _stop_all(processes: Sequence[GatewayProcess]) -> None:
    for process in processes:
        process.stop()


def _set_up_django(database_url: str, redis_url: str) -> None:
    os.environ.update(
        DJANGO_SETTINGS_MODULE=SETTINGS_MODULE, DATABASE_URL=database_url, REDIS_URL=redis_url
    )
    import django

    django.setup()
    from django.core.management import call_command

    # Loads hrc's Celery app, as Django projects do at start-up: without it a
    # shared task sent from this process would go to Celery's default app.
    import hrc.celery  # noqa: F401

    call_command("migrate", verbosity=0, interactive=False)


def _close_connections() -> None:
    from django.db import connections

    connections.close_all()


def _populate(workdir: Path, cobots: int, gateways: list[GatewayProcess]) -> dict[str, Any]:
    """An organisation with an engineer and an operator, the cobots, the two patterns published."""
    from django.contrib.auth.models import User

    from hrc.cases import services
    from hrc.cobots.drivers.runner import driver_for
    from hrc.cobots.models import Cobot
    from hrc.cobots.simulated import GatewayProcess
    from hrc.organisations import services as organisations
    from hrc.organisations.choices import Role
    from hrc.patterns import services as patterns

    organisation = organisations.create_organisation(name="Bench plant", slug="bench-plant")
    engineer = User.objects.create_user("bench-engineer")
    organisations.add_member(organisation, engineer, Role.ENGINEER)
    credentials = {"username": "bench-operator", "password": uuid.uuid4().hex}
    operator = User.objects.create_user(**credentials)
    organisations.add_member(organisation, operator, Role.OPERATOR)
    made: list[Cobot] = []
    for number in range(1, cobots + 1):
        name = f"cobot{number}"
        gateway = GatewayProcess(name, workdir / f"{name}.json", time_scale=0.0)
        gateways.append(gateway.start())
        driver = driver_for(name, gateway.endpoint, step_timeout=30.0)
        driver.call("PowerOn", timeout=30)
        driver.call("SelectProgram", PROGRAM)
        driver.call("StartProgram")
        driver.close()  # this process drives no cobot during the run
        made.append(Cobot.objects.create(organisation=organisation, name=name, endpoint=gateway.endpoint))  # fmt: skip
    versions = {}
    mapping = {"o": {"users": [operator.pk]}, "c": {"cobot": made[0].pk}}
    for key, document in (("signal", signal_pattern()), ("loop", loop_pattern())):
        draft = patterns.create_pattern(organisation, name=document["name"], created_by=engineer, draft=document)  # fmt: skip
        versions[key] = patterns.publish_pattern(draft, published_by=engineer)
        services.set_default_actor_mapping(versions[key], mapping)
    return {"operator": operator, "credentials": credentials, "cobots": made, **versions}
