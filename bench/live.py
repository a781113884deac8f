"""`make bench` (fourth part): the live layer — from a cobot's output register to the new task
on 200 connected tablets, against the channel layer's own floor.

Everything runs on this machine and is thrown away afterwards: a scratch
PostgreSQL database, a private redis-server (Celery broker and channel
layer), one real Celery worker, one simulated OPC UA gateway (TIME_SCALE),
the ASGI server (daphne, as production runs it) in its own process, and N WebSocket
clients (the `websockets` library) on one asyncio loop in this process, each
signed in as an operator of its own.

Ours: a case starts whose first task is a cobot step and whose next is an
operator task. An observer subscribed to the gateway notes when the cobot's
output Int26 (the step's fencing token) becomes the job's id — the cobot
saying "done"; each client notes when it has received and applied (in its
case's seq order) the delta that offers the operator task. One sample per
client per case. Floor, in the same run: a bare group_send of one delta from
this process to the group all N sockets joined, until each client has it.
Target: ours p99 <= 100 ms.

Results: bench/results/live-<UTC>.json (and -latest.json), and a table.
"""

from __future__ import annotations

import argparse
import asyncio
import contextlib
import json
import signal
import sys
import tempfile
import threading
import time
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field, replace
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

from bench.report import load_average, print_load, settings_json, write_results
from bench.runtime_rig import (
    RESULTS_DIR,
    SETTINGS_MODULE,
    ApiServer,
    Observer,
    _set_up_django,
    database_server,
    scratch_database,
    summary,
)
from tests.support.polling import until

TARGET_P99_MS = 100.0
PROGRAM, STEP = "Coexistence_PickAndPlace", 3  # "pick": a 2 s wait
# Simulated time at a tenth: the pick takes 0.2 s, as a real step takes its time, so what
# its start sent has reached the tablets before it ends (a zero-time step would measure
# the queue of its own start's deltas instead).
TIME_SCALE = 0.1
SHAPE = "p0 → tc1 (cobot: pick) → p1 → to1 (operator: check) → p2"


@dataclass(frozen=True)
class Settings:
    clients: int = 200
    samples: int = 30  # cases, each timed on every client
    warmup: int = 3  # untimed cases first
    floor_samples: int = 30
    quick: bool = False
    results_dir: Path = RESULTS_DIR


QUICK: dict[str, Any] = {"clients": 20, "samples": 5, "warmup": 1, "floor_samples": 5}


def pattern() -> dict[str, Any]:
    """The cobot finishes a step; the operator's task is offered (SHAPE)."""
    step = {"step": {"program": PROGRAM, "number": STEP}, "timeout": 30}
    return {
        "format": "hrc-pattern/1",
        "name": "bench: cobot, then operator",
        "actors": [{"id": "c", "type": "cobot", "program": PROGRAM}, {"id": "o", "type": "operator"}],
        "processes": [{
            "id": "N", "workpiece": "w", "actors": ["c", "o"],
            "places": [{"id": "p0", "tokens": 1}, {"id": "p1"}, {"id": "p2"}],
            "transitions": [
                {"id": "tc1", "performer": "c", "label": "pick", "task": step},
                {"id": "to1", "performer": "o", "label": "check"},
            ],
            "arcs": [["p0", "tc1"], ["tc1", "p1"], ["p1", "to1"], ["to1", "p2"]],
        }],
    }  # fmt: skip


# The tablets: N WebSocket clients on one loop ---------------------------------------------------


@dataclass
class Tablet:
    """One client: applies case deltas in seq order and notes when the awaited ones arrive."""

    cookie: str
    known: dict[int, int] = field(default_factory=dict)
    holes: int = 0


class Tablets:
    """N sockets on a loop of their own thread; `expect` says what to time, `wait` collects it."""

    def __init__(self, ws_url: str, origin: str, cookies: list[str]) -> None:
        self.ws_url, self.origin = ws_url, origin
        self.tablets = [Tablet(cookie) for cookie in cookies]
        self.loop = asyncio.new_event_loop()
        self.thread = threading.Thread(target=self.loop.run_forever, daemon=True)
        self._wanted: Callable[[dict[str, Any]], bool] = lambda event: False
        self._seen: dict[int, float] = {}
        self._all_seen = threading.Event()
        self._tasks: list[asyncio.Task[None]] = []
        self.closed: list[int] = []

    def start(self) -> None:
        self.thread.start()
        asyncio.run_coroutine_threadsafe(self._connect_all(), self.loop).result(120)

    async def _connect_all(self) -> None:
        from websockets.asyncio.client import connect

        for index, tablet in enumerate(self.tablets):
            socket = await connect(
                self.ws_url, additional_headers={"Cookie": tablet.cookie, "Origin": self.origin},
                max_queue=None, ping_interval=None,  # the server pings; a loaded machine is slow
            )  # fmt: skip
            snapshot = json.loads(await socket.recv())
            if snapshot.get("type") != "snapshot":
                raise RuntimeError(f"tablet {index} was refused: {snapshot}")
            tablet.known = {case["id"]: case["seq"] for case in snapshot["cases"]}
            self._tasks.append(asyncio.create_task(self._read(index, tablet, socket)))

    async def _read(self, index: int, tablet: Tablet, socket: Any) -> None:
        async for raw in socket:
            frame = json.loads(raw)
            for event in frame if isinstance(frame, list) else [frame]:
                self._apply(index, tablet, event)
        self.closed.append(index)  # the server closed it: wait() says so

    def _apply(self, index: int, tablet: Tablet, event: dict[str, Any]) -> None:
        """Applies a case delta in seq order (a hole is counted) and notes the awaited event."""
        if event.get("type") in ("case", "work-item", "incident"):
            known = tablet.known.get(event["case"], 0)
            if event["seq"] <= known:
                return
            if event["seq"] != known + 1:
                tablet.holes += 1  # a real tablet would resynchronise; count it
            tablet.known[event["case"]] = event["seq"]
        if self._wanted(event) and index not in self._seen:
            self._seen[index] = time.perf_counter()
            if len(self._seen) == len(self.tablets):
                self._all_seen.set()

    def expect(self, wanted: Callable[[dict[str, Any]], bool]) -> None:
        """From now on, note the first event of each tablet for which `wanted` holds."""

        def reset() -> None:
            self._seen, self._wanted = {}, wanted
            self._all_seen.clear()

        self.loop.call_soon_threadsafe(reset)
        time.sleep(0.001)  # let the loop take it before the event can happen

    def wait(self, timeout: float = 30.0) -> list[float]:
        """perf_counter() per tablet at which it had the expected event."""
        if not self._all_seen.wait(timeout):
            raise TimeoutError(
                f"{len(self._seen)} of {len(self.tablets)} tablets had the event; "
                f"sockets the server closed: {self.closed or 'none'}"
            )
        return list(self._seen.values())

    def close(self) -> None:
        async def cancel_all() -> None:
            for task in self._tasks:
                task.cancel()
            await asyncio.gather(*self._tasks, return_exceptions=True)

        with contextlib.suppress(Exception):
            asyncio.run_coroutine_threadsafe(cancel_all(), self.loop).result(30)
        self.loop.call_soon_threadsafe(self.loop.stop)
        self.thread.join(10)


# The cobot's output register ----------------------------------------------------------------


# The rig --------------------------------------------------------------------------------------


@dataclass
class Rig:
    organisation: Any
    version: Any
    cobot: Any
    tablets: Tablets
    observer: Observer  # the cobot's output Int26


@contextlib.contextmanager
def rig(settings: Settings, progress: Callable[[str], None]) -> Iterator[Rig]:
    from hrc.cobots.simulated import GatewayProcess
    from hrc_gateway import urua
    from tests.support.workers import RedisProcess, WorkerProcess

    with contextlib.ExitStack() as stack:
        workdir = Path(stack.enter_context(tempfile.TemporaryDirectory(prefix="hrc-bench-live-")))
        redis = RedisProcess(workdir).start()
        stack.callback(redis.stop)
        database_url = stack.enter_context(scratch_database(database_server()))
        progress(f"scratch database {database_url.rsplit('/', 1)[1]}, broker {redis.url}")
        _set_up_django(database_url, redis.url)
        stack.callback(_close_connections)
        gateway = GatewayProcess("cobot1", workdir / "cobot1.json", time_scale=TIME_SCALE).start()
        stack.callback(gateway.stop)
        made = _populate(gateway.endpoint, settings.clients)
        environment = {
            "DJANGO_SETTINGS_MODULE": SETTINGS_MODULE, "DATABASE_URL": database_url,
            "REDIS_URL": redis.url, "HRC_SWEEP_SECONDS": "0.5",
        }  # fmt: skip
        worker = WorkerProcess(workdir, name="worker0", environment=environment, beat=True)
        worker.start()
        stack.callback(worker.stop)
        server = ApiServer(workdir, environment).start()  # the runtime bench's web process
        stack.callback(server.stop)
        progress(f"{settings.clients} tablets connecting")
        url = f"ws://127.0.0.1:{server.port}/ws/live/?organisation={made['organisation'].pk}"
        tablets = Tablets(url, f"http://127.0.0.1:{server.port}", made.pop("cookies"))
        tablets.start()
        stack.callback(tablets.close)
        observer = Observer(
            gateway.endpoint, "cobot1", [urua.FENCE_STEP], direction="Outputs"
        ).start()
        stack.callback(observer.close)
        yield Rig(tablets=tablets, observer=observer, **made)


def _populate(endpoint: str, clients: int) -> dict[str, Any]:
    from django.contrib.auth import BACKEND_SESSION_KEY, HASH_SESSION_KEY, SESSION_KEY
    from django.contrib.auth.models import User
    from django.contrib.sessions.backends.db import SessionStore

    from hrc.cases import services
    from hrc.cobots.drivers.runner import driver_for
    from hrc.cobots.models import Cobot
    from hrc.organisations import services as organisations
    from hrc.organisations.choices import Role
    from hrc.patterns import services as patterns

    organisation = organisations.create_organisation(name="Bench plant", slug="bench-plant")
    engineer = User.objects.create_user("bench-engineer")
    organisations.add_member(organisation, engineer, Role.ENGINEER)
    driver = driver_for("cobot1", endpoint, step_timeout=30.0)
    driver.call("PowerOn", timeout=30)
    driver.call("SelectProgram", PROGRAM)
    driver.call("StartProgram")
    driver.close()
    cobot = Cobot.objects.create(organisation=organisation, name="cobot1", endpoint=endpoint)
    cookies, operators = [], []
    for number in range(clients):
        user = User.objects.create_user(f"bench-operator-{number}")
        organisations.add_member(organisation, user, Role.OPERATOR)
        operators.append(user.pk)
        session = SessionStore()
        session[SESSION_KEY] = str(user.pk)
        session[BACKEND_SESSION_KEY] = "django.contrib.auth.backends.ModelBackend"
        session[HASH_SESSION_KEY] = user.get_session_auth_hash()
        session.create()
        cookies.append(f"sessionid={session.session_key}")
    document = pattern()
    draft = patterns.create_pattern(organisation, name=document["name"], created_by=engineer, draft=document)  # fmt: skip
    version = patterns.publish_pattern(draft, published_by=engineer)
    services.set_default_actor_mapping(
        version, {"o": {"users": operators[:1]}, "c": {"cobot": cobot.pk}}
    )
    return {"organisation": organisation, "version": version, "cobot": cobot, "cookies": cookies}


def _close_connections() -> None:
    from django.db import connections

    connections.close_all()


# The measurements -----------------------------------------------------------------------------


def measure_ours(bench: Rig, settings: Settings, progress: Callable[[str], None]) -> dict[str, Any]:
    from hrc.cases import services
    from hrc.cases.models import CaseEvent, Job
    from hrc_gateway import urua

    latencies: list[float] = []
    spreads: list[float] = []
    to_offer: list[float] = []
    progress(f"ours: {settings.warmup} + {settings.samples} cases on {settings.clients} tablets")
    for index in range(settings.warmup + settings.samples):
        bench.tablets.expect(_offers_the_operator_task)
        case = services.start_case(bench.version, started_by=None)
        jobs = Job.objects.filter(case=case).values_list("pk", flat=True)
        job_id = until(jobs.first, interval=0.001)
        applied = bench.tablets.wait()
        done = bench.observer.seen_at(urua.FENCE_STEP, job_id)
        if index >= settings.warmup:
            latencies += [(at - done) * 1000 for at in applied]
            spreads.append((max(applied) - min(applied)) * 1000)
            offered = CaseEvent.objects.get(case=case, type="task-offered", task="to1").at
            to_offer.append(
                (offered.timestamp() - bench.observer.wall_at(urua.FENCE_STEP, job_id)) * 1000
            )
    return {
        "ours": summary(latencies),
        "register_to_offer_recorded": summary(to_offer),
        "spread_first_to_last_tablet": summary(spreads),
        "holes": sum(tablet.holes for tablet in bench.tablets.tablets),
    }


def _offers_the_operator_task(event: dict[str, Any]) -> bool:
    return (
        event.get("type") == "work-item"
        and event["event"] == "task-offered"
        and event["item"]["task"] == "to1"
    )


def _is_case(marker: int) -> Callable[[dict[str, Any]], bool]:
    return lambda event: event.get("type") == "case" and event["case"] == marker


def measure_floor(bench: Rig, settings: Settings) -> dict[str, Any]:
    """A bare group_send of one delta to the organisation's group, until every tablet has it."""
    from channels.layers import get_channel_layer

    from hrc.live import groups, sender
    from hrc.live.events import CaseDelta

    layer = get_channel_layer()
    organisation = bench.organisation.pk
    loop = asyncio.new_event_loop()
    latencies: list[float] = []
    try:
        for index in range(settings.warmup + settings.floor_samples):
            marker = 2_000_000_000 + index
            delta: CaseDelta = {
                "type": "case", "case": marker, "seq": 1, "event": "case-started",
                "data": {"id": marker, "seq": 1, "status": "running", "name": "", "cobots": []},
            }  # fmt: skip
            group = groups.organisation_group(organisation)
            message = sender.Send([group], organisation, [delta], [""]).message()
            bench.tablets.expect(_is_case(marker))
            sent = time.perf_counter()
            loop.run_until_complete(layer.group_send(group, message))
            applied = bench.tablets.wait()
            if index >= settings.warmup:
                latencies += [(at - sent) * 1000 for at in applied]
            time.sleep(0.05)
    finally:
        loop.close()
    return summary(latencies)


# The run, the report, the table ---------------------------------------------------------------


def run(settings: Settings, progress: Callable[[str], None] = print) -> dict[str, Any]:
    from bench.runtime import machine

    load_before = load_average()
    with rig(settings, progress) as bench:
        host = machine()
        floor = measure_floor(bench, settings)
        ours = measure_ours(bench, settings, progress)
    report = {
        "benchmark": "live",
        "when": datetime.now(UTC).isoformat(timespec="seconds"),
        "machine": host,
        "load_average": {"before": load_before, "after": load_average()},
        "settings": settings_json(settings),
        "pattern": SHAPE,
        **ours,
        "floor": floor,
        "ratio_p50": round(ours["ours"]["p50_ms"] / floor["p50_ms"], 2),
        "ratio_p99": round(ours["ours"]["p99_ms"] / floor["p99_ms"], 2),
        "target_p99_ms": TARGET_P99_MS,
        "meets_target": ours["ours"]["p99_ms"] <= TARGET_P99_MS,
    }
    write_results(settings.results_dir, "live", report)
    return report


def print_table(report: Mapping[str, Any]) -> None:
    settings = report["settings"]
    print(f"\nLive: cobot's output register → new task applied on {settings['clients']} tablets "
          f"({settings['samples']} cases)")  # fmt: skip
    print(f"{'':52} {'p50 ms':>8} {'p99 ms':>8} {'max ms':>8}")
    rows = [
        ("ours: output Int26 = job id → task applied", report["ours"]),
        ("  of which: → the worker records the offer", report["register_to_offer_recorded"]),
        ("  spread: first → last tablet, per case", report["spread_first_to_last_tablet"]),
        ("floor: bare group_send → delta on every tablet", report["floor"]),
    ]
    for label, row in rows:
        print(f"{label:52} {row['p50_ms']:8.3f} {row['p99_ms']:8.3f} {row['max_ms']:8.3f}")
    print(f"ours / floor: p50 {report['ratio_p50']:.2f}, p99 {report['ratio_p99']:.2f}; "
          f"holes seen by tablets: {report['holes']}")  # fmt: skip
    verdict = "meets" if report["meets_target"] else "MISSES"
    print(f"target p99 <= {TARGET_P99_MS:g} ms: {verdict}")
    print_load(report)


def parse_args(argv: Sequence[str] | None = None) -> Settings:
    parser = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    parser.add_argument("--quick", action="store_true", help=f"a small run: {QUICK}")
    for name in ("clients", "samples", "warmup", "floor_samples"):
        parser.add_argument(f"--{name.replace('_', '-')}", type=int)
    parser.add_argument("--results-dir", type=Path, default=RESULTS_DIR)
    arguments = parser.parse_args(argv)
    settings = replace(Settings(), quick=arguments.quick, results_dir=arguments.results_dir)
    if arguments.quick:
        settings = replace(settings, **QUICK)
    for name in ("clients", "samples", "warmup", "floor_samples"):
        value = getattr(arguments, name)
        if value is not None:
            if value < (0 if name == "warmup" else 1):
                parser.error(f"--{name.replace('_', '-')} must be at least 1 (warmup: 0)")
            settings = replace(settings, **{name: value})
    return settings


def main(argv: Sequence[str] | None = None) -> None:
    settings = parse_args(argv)
    signal.signal(signal.SIGTERM, lambda signum, frame: sys.exit(128 + signum))
    print_table(run(settings, progress=lambda line: print(line, file=sys.stderr, flush=True)))


if __name__ == "__main__":
    main()
