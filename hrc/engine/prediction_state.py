"""The state a prediction's simulation (prediction_run.py) keeps: the net's markings as
reached, case data as reached, and the cases, work items, teams, cobots and devices.

What makes many cases fast: a `Node` works out what the net allows in a marking once, a
`DataState` everything computed over one state of case data once, and every case that
reaches them shares them; a case is then mostly dictionary look-ups between its events.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

from hrc.engine.petri import Marking
from hrc.engine.runtime import AreaRule, CaseNet

Diff = tuple[tuple[str, ...], tuple[str, ...]]  # (withdrawn, offered): Node.offers_after's
CompletionPlan = tuple["Node", Diff | None, str | None]  # Node.completes' (which see)

# The net's states, worked out once per marking ---------------------------------------------


class Node:
    """A marking some case reached, with what the net allows in it; shared by every case."""

    __slots__ = (
        "after", "calm", "completable", "completes", "dead", "diffs", "eager", "final", "groups",
        "marking", "messages", "startable", "startable_set", "starts", "timers", "to_offer",
    )  # fmt: skip

    def __init__(self, net: CaseNet, marking: Marking) -> None:
        self.marking = marking
        self.startable = tuple(net.startable(marking))
        self.startable_set = frozenset(self.startable)
        # What a case resting here has offered: its startable tasks that are not running (a
        # running task is not offered again, progress._offer_and_withdraw).
        self.to_offer = tuple(t for t in self.startable if not marking.get(f"running:{t}"))
        self.eager = tuple(t for t in net.eager if t.is_enabled(marking))
        self.messages = tuple(net.waiting_messages(marking))
        self.timers = tuple(net.waiting_timers(marking))
        self.final = net.is_final(marking)
        running = any(marking.get(f"running:{t}") for t in net.tasks)
        self.dead = not (self.final or self.startable or self.messages or self.timers or running)
        # Nothing fires here by itself, ends the case or waits: arriving changes only the offers.
        self.calm = not (self.eager or self.messages or self.final or self.timers or self.dead)
        self.after: dict[str, Node] = {}  # silent transition id → the node after firing it
        # Task → the node after its start, and whether the start leaves nothing else to do
        # (no firing, no change of offers but the started task's): then no advance follows.
        self.starts: dict[str, tuple[Node, bool]] = {}
        # Task → the node after its completion, the offers that change then when that is all
        # there is to it (None: an advance follows), and the one task they offer, if so.
        self.completes: dict[str, CompletionPlan] = {}
        self.diffs: dict[Node | None, Diff] = {}
        self.groups: dict[str, tuple[str, ...]] = {}
        self.completable: dict[str, bool] = {}  # task → whether its completion is enabled

    def offers_after(self, rest: Node | None) -> Diff:
        """(withdrawn, offered): how a case that rested at `rest` (None: a new case) brings its
        work items in line with this node."""
        diff = self.diffs.get(rest)
        if diff is None:
            before = rest.to_offer if rest is not None else ()
            withdrawn = tuple(t for t in before if t not in self.to_offer)
            offered = tuple(t for t in self.to_offer if t not in before)
            diff = self.diffs[rest] = (withdrawn, offered)
        return diff

    def can_complete(self, net: CaseNet, task: str) -> bool:
        known = self.completable.get(task)
        if known is None:
            known = self.completable[task] = net.can_complete(self.marking, task)
        return known

    def competing(self, net: CaseNet, transition: str, among: tuple[str, ...]) -> tuple[str, ...]:
        """The transitions of `among` (enabled here) that take a token `transition` takes,
        `transition` first."""
        group = self.groups.get(transition)
        if group is None:
            inputs = {place for place, _ in net.transition(transition).pre}
            others = tuple(
                other
                for other in among
                if other != transition
                and any(place in inputs for place, _ in net.transition(other).pre)
            )
            group = self.groups[transition] = (transition, *others)
        return group


class DataState:
    """A case's data as some case reached it (never changed: a change makes a new one), with
    what was computed over it, so that cases on the same path compute each thing once."""

    __slots__ = ("after", "commands", "guards", "matches", "sends", "values")

    def __init__(self, values: Mapping[str, Any]) -> None:
        self.values = values
        self.after: dict[Any, DataState] = {}
        self.guards: dict[str, bool] = {}
        self.commands: dict[str, Mapping[str, Any]] = {}
        self.sends: dict[str, Message] = {}
        self.matches: dict[tuple[str, Message], bool] = {}


class Message:
    """A message a case sent itself; compared by identity (each is made once per data state)."""

    __slots__ = ("correlation", "name", "payload")

    def __init__(self, name: str, correlation: dict[str, Any], payload: dict[str, Any]) -> None:
        self.name, self.correlation, self.payload = name, correlation, payload


class TaskProfile:
    """What a simulation knows of a task before any case runs it, in one record: every start
    and completion reads several of these, and one look-up is cheaper than one per fact."""

    __slots__ = (
        "changes_data", "commanded", "counts", "fixed", "kind", "rules", "sample", "task", "watched",
    )  # fmt: skip

    def __init__(
        self,
        task: str,
        kind: str,
        *,
        fixed: float | None,
        sample: Callable[[], float] | None,
        commanded: bool,
        changes_data: bool,
        watched: bool,
        rules: tuple[AreaRule, ...],
        counts: list[float],
    ) -> None:
        self.task = task
        self.kind = kind  # operator, cobot or device
        # Its time: `fixed`, else one drawn by `sample`, else (both None) the plant's.
        self.fixed = fixed
        self.sample = sample
        # Its command is made as it is offered (the job's): what the plant times or answers,
        # or what a device call's happy answer reads (its "expected").
        self.commanded = commanded
        self.changes_data = changes_data  # its completion may change the case data
        # Its start or completion does more than move the marking: a message, a shared area,
        # the trace.
        self.watched = watched
        self.rules = rules  # a space constraint's task: its area's rules as it enters
        self.counts = counts  # the tally's [completions, seconds run, seconds waited]


# Cases, work items and who does them ------------------------------------------------------------


class Resource:
    """An operator team, a cobot or a device: who does the work of an actor in a case."""

    __slots__ = (
        "busy", "busy_seconds", "held_seconds", "held_since", "holds", "interrupted_seconds",
        "key", "kind", "machine", "pauses", "people", "queue", "ready", "waited",
        "waiting_seconds", "work_items",
    )  # fmt: skip

    def __init__(self, key: str, kind: str, people: int | None) -> None:
        self.key = key
        self.kind = kind
        self.machine = kind != "operator"  # a cobot or a device
        self.ready = False  # listed to take work (it has new work, or is newly free)
        self.people = people  # a cobot's or a device's: 1
        self.busy = 0  # persons at work; a cobot's running steps (0 or 1)
        self.queue: list[WorkItem] = []  # offered work, oldest first (withdrawn ones dropped late)
        self.holds: dict[CaseState, int] = {}  # steps done whose completion a func constraint holds
        self.pauses = 0  # open pauses of its steps: it takes no other step meanwhile
        self.busy_seconds = 0.0
        self.held_seconds = 0.0
        self.held_since = 0.0
        self.interrupted_seconds = 0.0
        self.waiting_seconds = 0.0
        self.waited = 0
        self.work_items = 0


class CaseState:
    __slots__ = (
        "answers", "assigned", "data", "ended", "finished", "index", "interruptions", "items",
        "last", "node", "outbox", "rest", "running", "started", "tasks_run", "timers",
    )  # fmt: skip

    def __init__(
        self,
        index: int,
        node: Node,
        data: DataState,
        assigned: dict[str, tuple[Resource, TaskProfile]],
        now: float,
    ) -> None:
        self.index = index
        self.node = node
        self.rest: Node | None = None  # where the latest advance left it: its items are
        # rest.to_offer
        self.data = data
        self.assigned = assigned  # task → the team, cobot or device doing it in this case,
        # and the task's profile
        self.started = now
        self.ended = False
        self.items: dict[str, WorkItem] = {}  # offered, not started: one per task at most
        self.running: dict[str, WorkItem] = {}  # started, not completed nor cancelled
        self.finished: list[
            WorkItem
        ] = []  # running, done, the completion held by a func constraint
        self.interruptions: list[
            tuple[WorkItem, WorkItem, str]
        ] = []  # (held, by, "pause" or "slow")
        self.outbox: list[Message] = []
        self.timers: dict[str, float] = {}  # armed timer transition → when it rings
        self.answers: dict[str, int] = {}  # task → how often its operator has answered its form
        self.tasks_run = 0
        self.last: WorkItem | None = None  # the latest completed


class WorkItem:
    """A work item: offered, then started and completed, or withdrawn (or cancelled).

    Made for every task a case runs, so it sets at its offer only what is read before its
    start; the rest is set as it comes to matter (`started`, `work` at its start, `command`
    for a task whose command is made as it is offered, `entered`, `remaining`, `since`,
    `pauses` and `slows` at the start of a space constraint's task)."""

    __slots__ = (
        "by_start", "case", "command", "completed", "done", "enabled_by", "entered", "offered",
        "pauses", "profile", "rate", "released_by", "remaining", "resource", "since", "slows",
        "started", "task", "version", "withdrawn", "work",
    )  # fmt: skip

    done: bool
    started: float
    work: float  # its time at full speed
    remaining: float  # of `work`, at `since`
    since: float
    pauses: int  # open interruptions pausing it, slowing it
    slows: int
    command: Mapping[str, Any]  # the job's (commands.cobot_command)
    entered: bool  # a space constraint's task: its work has begun, in its area

    def __init__(
        self,
        case: CaseState,
        profile: TaskProfile,
        resource: Resource,
        now: float,
        enabled_by: WorkItem | None,
    ) -> None:
        self.case = case
        self.profile = profile
        self.task = profile.task
        self.resource = resource
        self.offered = now
        self.enabled_by = enabled_by  # whose start or completion offered it
        # Whether it was enabled_by's start that offered it (a func constraint's), not its end.
        self.by_start = enabled_by is not None and not enabled_by.done
        self.completed = -1.0
        self.rate = 1.0  # 0 while paused, the slow rate while slowed
        self.version = 0  # its end event in the heap carries it: a rate change makes a new one
        self.done = False  # its work is done (a completion may still be held)
        self.withdrawn = False  # withdrawn before it started, or cancelled while it ran
        self.released_by: WorkItem | None = None  # whose completion let its held completion go
