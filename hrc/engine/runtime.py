"""The firing rule at run time: what a running case may start, complete or fire next.

A `CaseNet` is a published pattern compiled once for running: its execution
net (execution.py), each task's configuration, the guards and messages of
its silent transitions, the task pairs of its space constraints,
and the data its cases start with. It holds no case state: every method takes the marking (and
case data) and returns the next marking, so the database row stays the one
truth and the same rule serves the runtime, the token game and the tests.

- Silent transitions fire at once (`settle`), in net order, when their guard
  holds; a message transition waits for its message instead, and a timer
  transition for its time (the caller keeps the clock and `ring`s it).
- A transition with `cancels` empties what it names when it fires; a task
  whose `running:` place it empties is cancelled (the caller compares).
- A task whose start is enabled is offered; starting one consumes its input
  tokens, so the other tasks of a deferred choice are no longer startable.
- time and func constraints are places of the execution net, so `start` and
  `complete` enforce them; space constraints are the runtime's to honour
  (`space_rules`: who waits and who is interrupted, `entering_area`).
"""

import copy
from collections import Counter
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, Final

from hrc.engine import expressions
from hrc.engine.execution import build_execution_net, constraint_places
from hrc.engine.model import Pattern
from hrc.engine.petri import Marking, NetTransition
from hrc.engine.taskconfig import (
    MessageConfig,
    SendConfig,
    TaskConfig,
    guard_of,
    initial_data,
    message_of,
    send_of,
    space_modes,
    task_config,
    timer_of,
)

# A guard-driven loop of silent transitions that never stops is a modelling
# fault; the runtime stops it here rather than spin.
MAX_SILENT_FIRINGS: Final = 1000


class RuntimeFault(Exception):
    """The case cannot go on as modelled (a guard failed, a silent loop never ends)."""


class NotEnabled(Exception):
    """A start, completion or message firing that the marking does not allow; says why."""


@dataclass(frozen=True)
class SpacePair:
    """A space constraint's two tasks, their actors' types and how they share the area."""

    first: str
    second: str
    kinds: tuple[str, str]  # the actor types of first and second: "operator" or "cobot"
    mode: str  # one of taskconfig.SPACE_MODES for the two types

    def other(self, task: str) -> str:
        return self.second if task == self.first else self.first

    def kind(self, task: str) -> str:
        return self.kinds[0] if task == self.first else self.kinds[1]


@dataclass(frozen=True)
class AreaRule:
    """What happens when a task starts while its space partner runs in the shared area: `held`
    is kept out ("refused": an operator, "wait": a cobot's step), or interrupted while it runs
    ("pause", "slow": a cobot), for as long as `by` runs."""

    held: str
    by: str
    mode: str  # "refused", "wait", "pause" or "slow"

    @property
    def keeps_out(self) -> bool:
        """The held task may not start until `by` has completed."""
        return self.mode in ("refused", "wait")


def entering_area(pair: SpacePair, entering: str) -> AreaRule:
    """Who waits and who is interrupted when `entering` starts while the other task of `pair`
    runs. A person is never paused by software: between operators the later one is refused;
    a cobot beside an operator is paused (it waits when it is the later one) or slowed (the
    later one starts slowly); between cobots the later step waits, or starts and pauses the
    one running."""
    occupant = pair.other(entering)
    kinds = (pair.kind(entering), pair.kind(occupant))
    if kinds == ("operator", "operator"):
        return AreaRule(entering, occupant, "refused")
    if kinds == ("cobot", "cobot"):
        if pair.mode == "pause":
            return AreaRule(occupant, entering, "pause")
        return AreaRule(entering, occupant, "wait")
    cobot, operator = (entering, occupant) if kinds[0] == "cobot" else (occupant, entering)
    if pair.mode == "slow":
        return AreaRule(cobot, operator, "slow")
    if entering == cobot:
        return AreaRule(cobot, operator, "wait")
    return AreaRule(cobot, operator, "pause")


@dataclass(frozen=True)
class Outgoing:
    """A message a transition sends, its expressions evaluated."""

    name: str
    correlation: dict[str, Any]
    payload: dict[str, Any]


class CaseNet:
    def __init__(self, pattern: Pattern) -> None:
        self.pattern = pattern
        self.net = build_execution_net(pattern)
        self._transitions = {t.id: t for t in self.net.transitions}
        places = constraint_places(pattern)
        self._needs = {place: c.needed() for place, c in places.items()}
        # func-done places: the supported task (its completion fills it) per place.
        self._supported = {p: c.first for p, c in places.items() if c.kind == "func-done"}
        self._initial_data = initial_data(pattern)
        self.tasks: dict[str, TaskConfig] = {}
        self.performers: dict[str, str] = {}
        self.labels: dict[str, str] = {}
        self.guards: dict[str, str] = {}
        self.messages: dict[str, MessageConfig] = {}
        self.sends: dict[str, SendConfig] = {}
        self.timers: dict[str, int] = {}
        for _, transition in pattern.transitions():
            self.labels[transition.id] = transition.label or transition.id
            send = send_of(transition)
            if send is not None:
                self.sends[transition.id] = send
            if transition.performer is not None:
                self.tasks[transition.id] = task_config(pattern, transition)
                self.performers[transition.id] = transition.performer
                continue
            guard = guard_of(transition)
            if guard is not None:
                self.guards[transition.id] = guard
            message = message_of(transition)
            if message is not None:
                self.messages[transition.id] = message
            timer = timer_of(transition)
            if timer is not None:
                self.timers[transition.id] = timer
        # The silent transitions settle fires: those waiting for neither a message nor a timer.
        self.eager: tuple[NetTransition, ...] = tuple(
            t
            for t in self.net.transitions
            if t.kind == "silent" and t.id not in self.messages and t.id not in self.timers
        )
        self._timed = tuple(t for t in self.net.transitions if t.id in self.timers)
        self._message_started = self._processes_started_by_a_message()
        self.space_pairs = self._space_pairs()
        self.space_tasks = frozenset(
            task for pair in self.space_pairs for task in (pair.first, pair.second)
        )
        # Tasks whose completion a constraint place can hold back (func): only
        # their finished steps need looking for again after each firing.
        self.holdable_tasks = frozenset(
            task
            for task in self.tasks
            if any(place in self._needs for place, _ in self._transitions[f"complete:{task}"].pre)
        )
        # Tasks whose start touches no place another transition takes from: starting one
        # enables, disables or rings nothing else, so nothing follows from it.
        self.starts_alone = frozenset(task for task in self.tasks if self._starts_alone(task))

    def _starts_alone(self, task: str) -> bool:
        start = self._transitions[f"start:{task}"]
        own = (start.id, f"complete:{task}")
        touched = {place for place, _ in (*start.pre, *start.post)} | set(start.resets)
        return not any(
            place in touched
            for transition in self.net.transitions
            if transition.id not in own
            for place, _ in transition.pre
        )

    def _processes_started_by_a_message(self) -> list[tuple[Marking, Marking]]:
        """(initial tokens, end tokens) of each process whose every first step waits for a
        message another process of the pattern sends (a pool of a BPMN collaboration that a
        message flow starts): while it holds just its initial tokens, nothing has started it.
        A process waiting for a message from outside the pattern keeps the case waiting."""
        sent = {send.name for send in self.sends.values()}
        started = []
        for process in self.pattern.processes:
            start = process.initial_marking()
            firsts = [
                transition
                for transition in self.net.transitions
                if any(place in start for place, _ in transition.pre)
            ]
            if (
                start
                and firsts
                and all(t.id in self.messages and self.messages[t.id].name in sent for t in firsts)
            ):
                end = Counter(process.sink_places())
                started.append((Marking(start), Marking(end)))
        return started

    def _space_pairs(self) -> tuple[SpacePair, ...]:
        pairs = []
        for constraint in self.pattern.constraints:
            first, second = constraint.source, constraint.target
            modes = space_modes(self.pattern, first, second)
            if constraint.type != "space" or not modes or first == second:
                continue
            mode = constraint.extra.get("interrupt", modes[0])
            kinds = (self.actor_type(first) or "", self.actor_type(second) or "")
            pairs.append(SpacePair(first, second, kinds, mode if mode in modes else modes[0]))
        return tuple(pairs)

    def space_rules(self, entering: str) -> list[AreaRule]:
        """For each space partner of `entering`, what happens if it runs when `entering` starts."""
        return [
            entering_area(pair, entering)
            for pair in self.space_pairs
            if entering in (pair.first, pair.second)
        ]

    def initial_data(self) -> dict[str, Any]:
        """The data a case starts with, a copy of its own (compiled nets are shared)."""
        return copy.deepcopy(self._initial_data)

    def transition(self, transition_id: str) -> NetTransition:
        return self._transitions[transition_id]

    def actor_type(self, task: str) -> str | None:
        actor = self.pattern.actor(self.performers.get(task, ""))
        return actor.type if actor else None

    @property
    def initial(self) -> Marking:
        return self.net.initial

    def is_final(self, marking: Marking) -> bool:
        """Whether the case has completed: each end place marked and nothing else, constraint
        places aside; the end of a process that completes implicitly may hold several tokens.
        A process still waiting for the message that starts it never ran (BPMN instantiates a
        pool at its message start event), so it counts as ended: a customer who never ordered
        leaves the supplier's pool unstarted, and the case has completed all the same."""
        if self.net.is_final(marking):
            return True
        never_ran = [
            (start, end)
            for start, end in self._message_started
            if all(marking.get(place) == count for place, count in start.items())
        ]
        if not never_ran:
            return False
        tokens = dict(marking.items())
        for start, end in never_ran:
            for place, count in start.items():
                tokens[place] -= count
            for place, count in end.items():
                tokens[place] = tokens.get(place, 0) + count
        return self.net.is_final(Marking(tokens))

    # Silent transitions ------------------------------------------------------------

    def settle(self, marking: Marking, data: Mapping[str, Any]) -> tuple[Marking, list[str]]:
        """Fires enabled silent transitions (guard holding, no message or timer awaited) until none
        is left.

        Returns the marking and the transitions fired, in order. Raises
        RuntimeFault when a guard cannot be evaluated or silent firings do not stop.
        """
        fired: list[str] = []
        while True:
            transition = self._next_silent(marking, data)
            if transition is None:
                return marking, fired
            if len(fired) >= MAX_SILENT_FIRINGS:
                raise RuntimeFault(
                    f"Silent transitions fired {MAX_SILENT_FIRINGS} times in a row "
                    f"({', '.join(fired[-3:])}, …): a loop whose guards never stop it."
                )
            marking = transition.fire(marking)
            fired.append(transition.id)

    def _next_silent(self, marking: Marking, data: Mapping[str, Any]) -> NetTransition | None:
        for transition in self.eager:
            if transition.is_enabled(marking) and self.guard_holds(transition.id, data):
                return transition
        return None

    def guard_holds(self, transition: str, data: Mapping[str, Any]) -> bool:
        """Whether the silent transition's guard holds over `data` (True without one).

        Raises RuntimeFault when the guard cannot be evaluated."""
        guard = self.guards.get(transition)
        if guard is None:
            return True
        try:
            return bool(expressions.evaluate(guard, {"data": data}))
        except expressions.ExpressionError as problem:
            raise RuntimeFault(f"The guard of {transition} failed: {problem}") from None

    def waiting_messages(self, marking: Marking) -> list[tuple[str, MessageConfig]]:
        """The message transitions enabled in `marking`: what the case waits to hear."""
        return [
            (t, message)
            for t, message in self.messages.items()
            if self._transitions[t].is_enabled(marking)
        ]

    def receive(self, marking: Marking, transition: str) -> Marking:
        """Fires a message transition; raises NotEnabled when the case is not waiting for it."""
        if transition not in self.messages:
            # Otherwise any silent transition (guard unchecked) or task start would fire here.
            raise NotEnabled(f"{transition} waits for no message.")
        return self._fire(marking, transition, f"the message of {transition}")

    def waiting_timers(self, marking: Marking) -> list[tuple[str, int]]:
        """The timer transitions enabled in `marking` and their durations in ms, in net order:
        what rings once it has stayed enabled that long."""
        return [(t.id, self.timers[t.id]) for t in self._timed if t.is_enabled(marking)]

    def ring(self, marking: Marking, transition: str) -> Marking:
        """Fires a timer transition whose time is up; raises NotEnabled when it is not an enabled
        timer transition. The caller settles after it, as after `receive`."""
        if transition not in self.timers:
            # Otherwise any silent transition (guard unchecked) or task start would fire here.
            raise NotEnabled(f"{transition} has no timer.")
        return self._fire(marking, transition, f"the timer of {transition}")

    # Tasks -------------------------------------------------------------------------

    def startable(self, marking: Marking) -> list[str]:
        """Tasks whose start is enabled, in net order: the work the case offers now."""
        return [t.task for t in self.net.transitions if t.kind == "start" and t.is_enabled(marking)]

    def can_start(self, marking: Marking, task: str) -> bool:
        return self._transitions[f"start:{task}"].is_enabled(marking)

    def can_complete(self, marking: Marking, task: str) -> bool:
        return self._transitions[f"complete:{task}"].is_enabled(marking)

    def start(self, marking: Marking, task: str) -> Marking:
        return self._fire(marking, f"start:{task}", f"{task} cannot start")

    def complete(self, marking: Marking, task: str) -> Marking:
        return self._fire(marking, f"complete:{task}", f"{task} cannot complete")

    def holding_for(self, task: str, marking: Marking | None = None) -> list[str]:
        """The supported tasks whose completion `task`'s completion waits for (func constraints),
        in constraint order: those still missing in `marking`, or all of them without one.
        [] when no func constraint holds `task` back."""
        return [
            self._supported[place]
            for place, weight in self._transitions[f"complete:{task}"].pre
            if place in self._supported and (marking is None or marking.get(place) < weight)
        ]

    def why_not(self, marking: Marking, transition: str) -> str:
        """What a transition waits for, as a person says it; "" when it is enabled."""
        missing = [
            self._needs.get(place) or _waiting_for(place)
            for place, weight in self._transitions[transition].pre
            if marking.get(place) < weight
        ]
        return "; ".join(missing)

    def _fire(self, marking: Marking, transition: str, what: str) -> Marking:
        net_transition = self._transitions.get(transition)
        if net_transition is None:
            raise NotEnabled(f"{what}: the pattern has no {transition}.")
        if not net_transition.is_enabled(marking):
            raise NotEnabled(f"{what}: it waits for {self.why_not(marking, transition)}.")
        return net_transition.fire(marking)


def _waiting_for(place: str) -> str:
    if place.startswith("running:"):
        return f"{place.removeprefix('running:')} to be running"
    return f"a token in {place}"


def apply_outputs(
    config: TaskConfig, task: str, result: Mapping[str, Any], data: Mapping[str, Any]
) -> dict[str, Any]:
    """The case data after a task: its outputs mapped in, or the whole result under its id.

    Raises RuntimeFault when an output expression fails on this result.
    """
    updated = dict(data)
    if config.outputs is None:
        if result:
            updated[task] = dict(result)
        return updated
    names = {"data": data, "result": result}
    for key, text in config.outputs.items():
        try:
            updated[key] = expressions.evaluate(text, names)
        except expressions.ExpressionError as problem:
            raise RuntimeFault(f"The output {key!r} of {task} failed: {problem}") from None
    return updated


def resolve(task: str, value: Any, data: Mapping[str, Any]) -> Any:
    """A configuration value with its expressions evaluated over the case data."""
    try:
        return expressions.resolve(value, {"data": data})
    except expressions.ExpressionError as problem:
        raise RuntimeFault(f"The configuration of {task} failed: {problem}") from None


def outgoing(
    transition: str, send: SendConfig, data: Mapping[str, Any], case: Mapping[str, Any]
) -> Outgoing:
    """The message `transition` sends, over the case data and the case (id, reference).

    Raises RuntimeFault when an expression fails."""
    names = {"data": data, "case": case}
    try:
        correlation = expressions.resolve(dict(send.correlation), names)
        payload = expressions.resolve(dict(send.payload), names)
    except expressions.ExpressionError as problem:
        raise RuntimeFault(
            f"The message {send.name!r} that {transition} sends failed: {problem}"
        ) from None
    return Outgoing(send.name, correlation, payload)


def correlates(
    message: MessageConfig,
    data: Mapping[str, Any],
    keys: Mapping[str, Any],
    case: Mapping[str, Any] | None = None,
) -> bool:
    """Whether a message with correlation `keys` is the one a case with `data` waits for;
    `case` is the case's id and reference, for correlations that read them."""
    if set(keys) != set(message.correlation):
        return False
    names = {"data": data, "case": dict(case or {})}
    for key, text in message.correlation.items():
        try:
            if not _same_json_value(expressions.evaluate(text, names), keys[key]):
                return False
        except expressions.ExpressionError:
            return False
    return True


def _same_json_value(ours: Any, theirs: Any) -> bool:
    """Equal as JSON values: true is not 1, "1" is not 1 (Python's == says True == 1)."""
    if isinstance(ours, bool) or isinstance(theirs, bool):
        return type(ours) is type(theirs) and ours == theirs
    return bool(ours == theirs)
