"""Running a pattern against simulated cobots, with operators who complete their tasks by themselves.

What `manage.py run_pattern --simulate` does, kept here so tests and the
benchmark drive the very same thing: a scratch organisation with one user per
operator actor and one simulated gateway (a real OPC UA server process) per
cobot actor; the pattern published there; N cases started; every operator
task started as soon as it is offered and completed after its time: drawn from
the task's distribution where `durations` gives one (hrc.engine.durations, the
prediction's own, from the run's seeded random source), else a short random
delay. Jobs run either on this process's threads (`inline`) or on Celery
workers started elsewhere.

What a simulated operator enters in a form is the engine's rule
(hrc.engine.forms.example_answers), the one the prediction follows: for each
required field, the field's `examples` in turn (the n-th time the operator
completes that task in a case it answers examples[n mod len], so a fixture's
`"examples": ["top right", "bottom left", …]` is the order that operator
mounts in), else its first `enum` value, its `default`, or a value of its
type.

A document may say how its cases differ from each other (the extended spot
taping: one case per operator, the second with the other workspace and the
cobots swapped) under `"simulation": {"cases": [...]}`; case i of a run is
`cases[i mod len]` (read as the prediction reads them,
hrc.engine.prediction.case_variants):

    {"name": "operator 2", "data": {"workspace": 1},
     "actors": {"o": "o2", "cL": "cR", "cR": "cL"}}

`data` is laid over the pattern's data; `actors` says who stands in for an
actor in that case: another actor of the same type (the cobots swapped), or
a new name, which gets a simulated operator or cobot of its own.
"""

from __future__ import annotations

import contextlib
import datetime as dt
import random
import re
import threading
import time
import uuid
from collections import Counter
from collections.abc import Iterator, Mapping
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from django.contrib.auth.models import User
from django.db import close_old_connections, connections
from django.utils import timezone

from hrc.cases import dispatch, jobs, services, timers
from hrc.cases.choices import OPEN_CASE_STATUSES, CaseStatus, WorkItemKind, WorkItemState
from hrc.cases.device_jobs import DEVICE_SESSION
from hrc.cases.models import Case, CaseEvent, Incident, WorkItem
from hrc.cases.nets import case_net
from hrc.cobots import services as cobot_services
from hrc.cobots.drivers.runner import SyncDriver, driver_for
from hrc.cobots.models import Cobot, Device
from hrc.cobots.simulated import GatewayProcess
from hrc.engine import prediction
from hrc.engine.durations import Duration
from hrc.engine.forms import example_answers
from hrc.engine.prediction import CaseVariant
from hrc.engine.runtime import CaseNet
from hrc.engine.taskconfig import DEVICE_KINDS, device_kind_of, device_kinds_called
from hrc.errors import Refusal
from hrc.organisations.choices import Role
from hrc.organisations.models import Membership, Organisation
from hrc.organisations.services import ensure_cell
from hrc.patterns import services as pattern_services
from hrc.patterns.models import PatternVersion
from hrc_gateway.sim.state import read_step_log

# The events a run reports, as issue #4's run_pattern contract names them.
REPORTED = {
    "task-started",
    "task-completed",
    "task-interrupted",
    "task-resumed",
    "case-completed",
    # what a case's processes tell each other or other cases ("send" and "message" keys)
    "message-sent",
    "message-received",
    # a timer transition fired (its duration times --time-scale); a running task it or another
    # transition cancelled (a "cancels" key)
    "timer-fired",
    "task-cancelled",
}
MESSAGES = {"message-sent", "message-received"}
FAILED = {"case-failed", "case-cancelled"}


@dataclass
class RunEvent:
    seq: int
    at: str
    case: int
    task: str | None
    actor: str | None
    event: str
    message: str | None = None  # a message event's message name

    def as_dict(self) -> dict[str, Any]:
        event = {
            "seq": self.seq,
            "at": self.at,
            "case": self.case,
            "task": self.task,
            "actor": self.actor,
            "event": self.event,
        }
        if self.message is not None:
            event["message"] = self.message
        return event


_STAND_IN = re.compile(r"[A-Za-z0-9_-]{1,40}")


def case_variants(document: Mapping[str, Any], net: CaseNet) -> tuple[CaseVariant, ...]:
    """The document's `"simulation": {"cases": [...]}` as the prediction reads them
    (hrc.engine.prediction.case_variants, checked as `predict` checks them), each stand-in
    also a name a simulated operator or gateway can take. Raises ValueError saying what is
    wrong."""
    variants = prediction.case_variants(document.get("simulation"), net)
    for variant in variants:
        for actor, stand_in in variant.actors.items():
            if not isinstance(stand_in, str) or not _STAND_IN.fullmatch(stand_in):
                raise ValueError(f"{variant.name}: {actor}'s stand-in must be a name of letters, digits, - or _.")  # fmt: skip
        # The prediction's own check (private to it today), so the two refuse alike.
        prediction.check_variant(variant, net)
    return variants


@dataclass
class Simulation:
    """One run: set up, run cases, report; use as a context manager so gateways stop."""

    document: Mapping[str, Any]
    workdir: Path
    time_scale: float = 0.05
    # Timers' own scale, where the model's timers are far longer than its steps (hours).
    timer_scale: float | None = None
    operator_delay: tuple[float, float] = (0.2, 1.0)  # seconds, times time_scale
    # An operator task's time by task id (seconds, times time_scale), drawn as the prediction
    # draws it; a task not named here takes operator_delay. A cobot's step takes its program's.
    durations: Mapping[str, Duration] = field(default_factory=dict)
    inline: bool = True
    seed: int | None = None
    # Whether the person at the pendant powers the cobots on before the run (a test of a
    # cobot left powered off says False).
    power_on: bool = True
    organisation: Organisation = field(init=False)
    version: PatternVersion = field(init=False)
    gateways: dict[str, GatewayProcess] = field(default_factory=dict, init=False)
    users: dict[str, User] = field(default_factory=dict, init=False)

    def __post_init__(self) -> None:
        self._random = random.Random(self.seed)
        self._stop = threading.Event()
        self._threads: list[threading.Thread] = []
        self._pool: ThreadPoolExecutor | None = None
        self._cobot_names: dict[str, str] = {}
        self._cobots: dict[str, Cobot] = {}
        self._devices: dict[str, Device] = {}
        self._with_devices = False
        self._variants: tuple[CaseVariant, ...] = ()
        self._started = 0
        self._answers: Counter[tuple[int, str]] = Counter()

    # Set-up ---------------------------------------------------------------------------

    def __enter__(self) -> Simulation:
        try:
            self._set_up()
        except BaseException:
            self.close()
            raise
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def _set_up(self) -> None:
        suffix = uuid.uuid4().hex[:8]
        self.organisation = Organisation.objects.create(
            name=f"run_pattern {suffix}", slug=f"run-pattern-{suffix}"
        )
        engineer = self._member(f"rp-{suffix}-engineer", Role.ENGINEER)
        pattern = pattern_services.create_pattern(
            self.organisation,
            name=str(self.document.get("name") or "pattern"),
            created_by=engineer,
            draft=dict(self.document),
        )
        self.version = pattern_services.publish_pattern(pattern, published_by=engineer)
        net = case_net(self.version)
        self._variants = case_variants(self.document, net)
        stand_ins = {actor.id: actor.id for actor in net.pattern.actors}
        for variant in self._variants:
            # A new name stands in like the first actor it stands in for (its program).
            stand_ins |= {
                name: actor for actor, name in variant.actors.items() if name not in stand_ins
            }
        types = {actor.id: actor.type for actor in net.pattern.actors}
        kinds = {actor.id: device_kind_of(actor) for actor in net.pattern.actors}
        self._with_devices = bool(device_kinds_called(net.pattern)) or any(kinds.values())
        for name, actor in stand_ins.items():
            if types[actor] == "operator":
                self.users[name] = self._member(f"rp-{suffix}-{name}", Role.OPERATOR)
            elif kinds[actor] is None:
                self._cobots[name] = self._simulated_cobot(name)
        for name, actor in stand_ins.items():
            kind = kinds[actor]
            if kind is not None:
                self._devices[name] = self._device_for(name, kind)
        mapping = {actor.id: self._binding(actor.id) for actor in net.pattern.actors}
        services.set_default_actor_mapping(self.version, mapping)

    def _binding(self, stand_in: str) -> dict[str, Any]:
        if stand_in in self.users:
            return {"users": [self.users[stand_in].pk]}
        if stand_in in self._devices:
            return {"device": self._devices[stand_in].pk}
        return {"cobot": self._cobots[stand_in].pk}

    def _device_for(self, stand_in: str, kind: str) -> Device:
        """A device actor's device, served beside a cobot as a cell's devices are: the first
        device actor of a kind gets the first cobot's cell's, the next the next cobot's (each
        operator's own linear axis in the extended spot taping), cycling when actors outnumber
        the cobots; a gateway of its own when the pattern has no cobot."""
        if not self._cobots:
            self._cobots[stand_in] = self._simulated_cobot(stand_in)
        taken = sum(device.kind == kind for device in self._devices.values())
        cobots = list(self._cobots.values())
        return Device.objects.get(gateway=cobots[taken % len(cobots)], kind=kind)

    def _member(self, username: str, role: str) -> User:
        user = User.objects.create_user(username)
        Membership.objects.create(user=user, organisation=self.organisation, role=role)
        return user

    def _simulated_cobot(self, actor: str) -> Cobot:
        """A fresh simulated cobot, powered on with its brakes released as the person at the
        pendant does when a shift starts; loading and playing each step's program is left to
        the worker (jobs._prepare), as on a plant."""
        name = f"{actor}-{self.organisation.slug}"
        gateway = GatewayProcess(name, self.workdir / f"{name}.json", time_scale=self.time_scale)
        self.gateways[actor] = gateway.start()
        self._cobot_names[actor] = name
        driver = driver_for(name, gateway.endpoint, step_timeout=30.0)
        if self.power_on:
            driver.call("PowerOn", timeout=30)  # the simulator's PowerOn releases the brakes too
        if not self._with_devices:
            return Cobot.objects.create(
                organisation=self.organisation, name=name, endpoint=gateway.endpoint
            )
        # Each cobot stands in a cell of its own, with every kind of device beside it on its
        # gateway (the simulator serves them all under Devices/).
        ensure_cell(self.organisation, actor)
        cobot = Cobot.objects.create(
            organisation=self.organisation, name=name, endpoint=gateway.endpoint, cell=actor
        )
        for kind in DEVICE_KINDS:
            cobot_services.create_device(
                self.organisation, name=f"{kind}-{actor}", kind=kind, cell=actor, gateway=cobot
            )
        return cobot

    def cobot(self, actor: str) -> SyncDriver:
        """A driver to the actor's simulated cobot (or a stand-in's, by its name), to look at it
        or to play the person at the cell."""
        return driver_for(self._cobot_names[actor], self.gateways[actor].endpoint)

    def executed_steps(self, actor: str) -> tuple[int, list[str]]:
        """What the actor's simulated cobot counted: (executions, the tokens of the latest ones)."""
        driver = self.cobot(actor)
        return int(driver.read("Simulator/Executions")), list(
            driver.read("Simulator/ExecutedSteps")
        )

    def step_log(self, actor: str) -> list[dict[str, Any]]:
        """The steps the actor's simulated cobot ran: when (Unix seconds) and at what override."""
        return read_step_log(self.workdir / f"{self._cobot_names[actor]}.json")

    def close(self) -> None:
        self._stop.set()
        for thread in self._threads:
            thread.join(10)
        if self._pool is not None:
            self._pool.shutdown(wait=True, cancel_futures=True)
        for actor, gateway in self.gateways.items():
            # The sessions first: a gateway gone under an open session makes noise in the log.
            with contextlib.suppress(Exception):
                driver_for(self._cobot_names[actor], gateway.endpoint).close()
            with contextlib.suppress(Exception):
                name = self._cobot_names[actor]
                driver_for(name, gateway.endpoint, session=DEVICE_SESSION).close()
            gateway.stop()

    # Running --------------------------------------------------------------------------

    def run(self, cases: int, timeout: float = 600.0) -> list[RunEvent]:
        """Starts `cases` cases and waits until each has ended; returns the run's events."""
        with self.running():
            started = self.start_cases(cases)
            self.wait(started, timeout)
        return self.events(started)

    def start_cases(self, count: int) -> list[int]:
        """Starts `count` cases; with case variants, each takes the next variant in turn."""
        started = []
        for _ in range(count):
            mapping: dict[str, Any] = {}
            data: Mapping[str, Any] = {}
            if self._variants:
                variant = self._variants[self._started % len(self._variants)]
                mapping = {actor: self._binding(name) for actor, name in variant.actors.items()}
                data = variant.data
            case = services.start_case(
                self.version, started_by=None, actor_mapping=mapping, data=data,
                timer_scale=self.time_scale if self.timer_scale is None else self.timer_scale,
            )  # fmt: skip
            started.append(case.pk)
            self._started += 1
        return started

    @contextlib.contextmanager
    def running(self, *, operators: bool = True) -> Iterator[None]:
        """Operators at work (and, inline, the jobs and the sweeper) while inside."""
        self._stop.clear()
        if operators:
            self._spawn(self._operators)
        try:
            if not self.inline:
                yield
                return
            self._pool = ThreadPoolExecutor(max_workers=len(self.gateways) + 2)
            self._spawn(self._sweeper)
            with dispatch.run_inline(self._pool):
                yield
        finally:
            self._stop.set()
            for thread in self._threads:
                thread.join(10)
            self._threads.clear()

    def _spawn(self, target: Any) -> None:
        thread = threading.Thread(target=target, daemon=True)
        thread.start()
        self._threads.append(thread)

    def wait(self, case_ids: list[int], timeout: float) -> bool:
        """Waits until every case has ended or waits for a person (an open incident); False on timeout."""
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            still_open = Case.objects.filter(pk__in=case_ids, status__in=OPEN_CASE_STATUSES)
            stuck = Incident.objects.filter(case__in=still_open, resolved_at__isnull=True)
            if not still_open.exclude(pk__in=stuck.values("case_id")).exists():
                return True
            time.sleep(0.05)
        return False

    def _sweeper(self) -> None:
        while not self._stop.wait(0.5):
            try:
                jobs.sweep()
                timers.sweep_timers()
            finally:
                close_old_connections()
        connections.close_all()

    def _operators(self) -> None:
        """Every operator starts an offered task at once and completes it after a short delay."""
        due: dict[int, float] = {}
        users = {user.pk: user for user in self.users.values()}
        while not self._stop.wait(0.01):
            try:
                self._operate(due, users)
            finally:
                close_old_connections()
        connections.close_all()  # this thread's: it would outlive the run

    def _operate(self, due: dict[int, float], users: dict[int, User]) -> None:
        items = WorkItem.objects.filter(
            case__organisation=self.organisation,
            kind=WorkItemKind.OPERATOR,
            state__in=[WorkItemState.OFFERED, WorkItemState.RUNNING],
            case__status=CaseStatus.RUNNING,
        ).prefetch_related("candidates")
        now = time.monotonic()
        for item in items:
            user = next((users[c.pk] for c in item.candidates.all() if c.pk in users), None)
            if user is None:
                continue
            with contextlib.suppress(Refusal):  # withdrawn or held meanwhile: try again later
                if item.state == WorkItemState.OFFERED:
                    services.start_work_item(item, user=user)
                    # From after the start's commit, not from `now`: the task's time counts
                    # from its task-started event, stamped inside start_work_item.
                    started = time.monotonic()
                    due[item.pk] = started + self._operator_seconds(item.task) * self.time_scale
                elif now >= due.setdefault(item.pk, now):
                    form = case_net(item.case.version).tasks[item.task].form
                    answer = self._answers[(item.case_id, item.task)]
                    services.complete_work_item(item, user=user, data=example_answers(form, answer))
                    self._answers[(item.case_id, item.task)] += 1

    def _operator_seconds(self, task: str) -> float:
        """How long the operator takes over `task`, before the time scale."""
        duration = self.durations.get(task)
        if duration is not None:
            return duration.sample(self._random)
        low, high = self.operator_delay
        return self._random.uniform(low, high)

    # Reporting ------------------------------------------------------------------------

    def events(self, case_ids: list[int]) -> list[RunEvent]:
        """The run's events in time order, numbered; an unfinished case gets case-failed."""
        rows = CaseEvent.objects.filter(case_id__in=case_ids).order_by("at", "case_id", "seq")
        ended: set[int] = set()
        events: list[tuple[dt.datetime, int, str | None, str | None, str, str | None]] = []
        for row in rows.values_list("at", "case_id", "task", "actor", "type", "detail"):
            at, case, task, actor, kind, detail = row
            if kind in FAILED:
                kind = "case-failed"
            if kind not in REPORTED and kind != "case-failed":
                continue
            if kind.startswith("case-"):
                ended.add(case)
                task = actor = ""
            name = detail.get("name") if kind in MESSAGES else None
            events.append((at, case, task or None, actor or None, kind, name))
        for case in case_ids:
            if case not in ended:
                events.append((timezone.now(), case, None, None, "case-failed", None))
        return [
            RunEvent(seq, at.isoformat(), case, task, actor, kind, name)
            for seq, (at, case, task, actor, kind, name) in enumerate(events, start=1)
        ]
