"""The simulation behind `prediction.predict`: an event heap driving `CaseNet` for many cases
that share operators' teams, cobots and devices. The rules it follows are prediction.py's;
the state it keeps is prediction_state.py's, what it counts prediction_report.py's.
"""

from __future__ import annotations

import random
from collections.abc import Mapping
from heapq import heappop, heappush
from itertools import count
from typing import TYPE_CHECKING, Any, Final

from hrc.engine.commands import cobot_command
from hrc.engine.durations import Duration, Fixed, sampler
from hrc.engine.forms import answer_period, example_answers
from hrc.engine.petri import Marking, NetTransition
from hrc.engine.prediction_report import Prediction, Tally, TraceEvent
from hrc.engine.prediction_state import (
    CaseState,
    CompletionPlan,
    DataState,
    Diff,
    Message,
    Node,
    Resource,
    TaskProfile,
    WorkItem,
)
from hrc.engine.runtime import (
    MAX_SILENT_FIRINGS,
    CaseNet,
    RuntimeFault,
    apply_outputs,
    correlates,
    outgoing,
)
from hrc.engine.taskconfig import TaskConfig

if TYPE_CHECKING:
    from hrc.engine.prediction import CaseVariant, Plant, Scenario

# advance() repeats settle → messages → held completions; each round takes a token.
MAX_ROUNDS: Final = 10_000
# The heap's mark, in place of a version, of a task entering its shared area.
ENTERS: Final = -1
# What message expressions read as `case`: messages stay within their case, so any one
# identity serves, and the same one for every case lets cases share what they computed.
CASE_NAMES: Final = {"id": 1, "reference": "predicted"}
# A device call's happy answer, by output name (a "found" count is the "expected" argument).
HAPPY_OUTPUTS: Final[Mapping[str, Any]] = {
    "detected": True,
    "authorized": True,
    "free": True,
    "result": "ok",
    "pose": [0.0] * 6,
}


# The simulation ------------------------------------------------------------------------------


class Simulation:
    """One prediction's run; `run()` once."""

    def __init__(
        self,
        net: CaseNet,
        scenario: Scenario,
        variants: tuple[CaseVariant, ...],
        plant: Plant | None,
    ) -> None:
        self.net = net
        self.scenario = scenario
        self.plant = plant
        self.rng = random.Random(scenario.seed)
        self.weights = scenario.weights
        self.trace_on = scenario.trace
        self.now = 0.0
        self.events = 0
        # (when, order, item, its version) for a work's end; (when, order, item, ENTERS) for
        # a space constraint's task entering its area after the hand-over; (when, order, None,
        # (case, timer transition, due)) for a timer.
        self.heap: list[tuple[float, int, WorkItem | None, Any]] = []
        self.order = count()  # ties on the heap go in push order
        self.nodes: dict[Marking, Node] = {}
        # Data states by value: cases whose processes wrote the same outputs in another order
        # share what was computed over them.
        self.data_states: dict[Any, DataState] = {}
        self.settled: dict[tuple[Node, DataState], tuple[Node, tuple[Message, ...]]] = {}
        # (node, data, *outbox) → (node, data, outbox) after advance's firing (_fire_all).
        self.fired_all: dict[tuple[Any, ...], tuple[Node, DataState, tuple[Message, ...]]] = {}
        # Choices drawn and cancelling transitions fired so far: what a firing that drew or
        # cancelled reached depends on more than where it began, and is not kept.
        self.draws = 0
        self.resets = 0
        self.resources: dict[str, Resource] = {}
        # Cobots and devices take their work before people do, as at run time (a completion
        # leases the step it enables in its own transaction; a tablet polls after).
        self.machines: list[Resource] = []
        self.teams: list[Resource] = []
        self.ready_machines: list[Resource] = []  # with new work, or newly free
        self.ready_teams: list[Resource] = []
        self.trigger: WorkItem | None = None  # whose start or work's end the current change follows
        self.open: dict[int, CaseState] = {}
        self.started_cases = 0
        self.tally = Tally(net)
        tasks = net.tasks
        self.start_ids = {t: f"start:{t}" for t in tasks}
        self.silent = {t.id: t for t in net.net.transitions if t.kind == "silent"}
        self.max_tasks = scenario.max_tasks_per_case
        self.handover = scenario.handover
        kinds = {t: _kind(c) for t, c in tasks.items()}
        self.durations, self.assumed = self._durations(kinds)
        self.profiles = {t: self._profile(t, c, kinds[t]) for t, c in tasks.items()}
        self.periods = {t: answer_period(c.form) for t, c in tasks.items()}
        self.answers: dict[tuple[str, int], dict[str, Any]] = {}
        # A weighted deferred choice offers some startable tasks only: the offers are then
        # worked out case by case instead of from the nodes.
        self.offer_by_node = not any(task in self.weights for task in tasks)
        self.variants = variants or (None,)
        self.roots = [
            self._data({**net.initial_data(), **(v.data if v else {})}) for v in self.variants
        ]
        self.assignments = [self._assign(v) for v in self.variants]

    def _durations(
        self, kinds: Mapping[str, str]
    ) -> tuple[dict[str, Duration | None], tuple[str, ...]]:
        """Each task's time; None: the plant's. And the tasks left to the defaults."""
        durations: dict[str, Duration | None] = {}
        assumed = []
        for task, kind in kinds.items():
            if task in self.scenario.durations:
                durations[task] = self.scenario.durations[task]
            elif kind != "operator" and self.plant is not None:
                durations[task] = None
            else:
                scenario = self.scenario
                durations[task] = (
                    scenario.operator_default if kind == "operator" else scenario.cobot_default
                )
                assumed.append(task)
        return durations, tuple(assumed)

    def _profile(self, task: str, config: TaskConfig, kind: str) -> TaskProfile:
        """What every start and completion of the task reads (after `_durations`)."""
        net, duration = self.net, self.durations[task]
        fixed = duration.seconds if isinstance(duration, Fixed) else None
        changes_data = _changes_data(config)
        plant_commands = self.plant is not None and kind != "operator"
        return TaskProfile(
            task,
            kind,
            fixed=fixed,
            sample=None if duration is None or fixed is not None else sampler(duration, self.rng),
            commanded=plant_commands or (kind == "device" and changes_data),
            changes_data=changes_data,
            watched=self.scenario.trace or task in net.sends or task in net.space_tasks,
            rules=tuple(net.space_rules(task)) if task in net.space_tasks else (),
            counts=self.tally.tasks[task],
        )

    def _assign(self, variant: CaseVariant | None) -> dict[str, tuple[Resource, TaskProfile]]:
        """Who does each task in a case of the variant: its actor's stand-in's team or cobot;
        a device call, its device (a device actor's own, or its cobot's of that kind). With
        the task's profile: an offer needs both, and one look-up finds them."""
        stand_ins = variant.actors if variant else {}
        assigned = {}
        for task, actor in self.net.performers.items():
            key = stand_ins.get(actor, actor)
            device = self.net.tasks[task].device
            found = self.net.pattern.actor(actor)
            if device is not None and not (found is not None and "device" in found.extra):
                key = f"{key}.{device.call.split('.')[0]}"
            profile = self.profiles[task]
            assigned[task] = (self._resource(key, profile.kind, actor), profile)
        return assigned

    def _resource(self, key: str, kind: str, actor: str) -> Resource:
        resource = self.resources.get(key)
        if resource is None:
            people: int | None = 1
            if kind == "operator":
                given = self.scenario.people
                people = given[key] if key in given else given.get(actor, 1)
            resource = self.resources[key] = Resource(key, kind, people)
            (self.teams if kind == "operator" else self.machines).append(resource)
        return resource

    # The event loop -------------------------------------------------------------------

    def run(self) -> Prediction:
        for _ in range(min(self.scenario.parallel, self.scenario.cases)):
            self._start_case()
        self._dispatch()
        heap, work_done, dispatch = self.heap, self._work_done, self._dispatch
        machines, teams = self.ready_machines, self.ready_teams
        while heap:
            self.now, _, item, subject = heappop(heap)
            if item is not None:
                if item.version == subject:
                    work_done(item)
                elif subject == ENTERS:
                    self._enter(item)
            else:
                case, transition, due = subject
                if not case.ended and case.timers.get(transition) == due:
                    self._ring(case, transition)
            if machines or teams:
                dispatch()
        self.events = next(self.order)  # every event pushed was popped: the pushes count them
        for case in list(self.open.values()):
            self._stick(case, self.tally.why_stuck(case), replace=False)
        return self.tally.report(
            self.scenario,
            span=self.tally.last_end or self.now,
            resources=(*self.teams, *self.machines),
            started=self.started_cases,
            events=self.events,
            assumed=self.assumed,
        )

    def _schedule(self, item: WorkItem) -> None:
        """Puts the end of the item's work on the heap, unless it is paused."""
        if item.rate > 0:
            end = self.now + item.remaining / item.rate
            heappush(self.heap, (end, next(self.order), item, item.version))

    def _wake(self, resource: Resource) -> None:
        """Lists the resource to take work (it has new work, or may have become free): one
        with nothing queued has nothing to take, and new work wakes it."""
        if resource.queue and not resource.ready:
            resource.ready = True
            (self.ready_machines if resource.machine else self.ready_teams).append(resource)

    def _data(self, values: Mapping[str, Any]) -> DataState:
        key = _frozen(values)
        state = self.data_states.get(key)
        if state is None:
            state = self.data_states[key] = DataState(values)
        return state

    def _node(self, marking: Marking) -> Node:
        node = self.nodes.get(marking)
        if node is None:
            node = self.nodes[marking] = Node(self.net, marking)
        return node

    def _fire(self, case: CaseState, transition: NetTransition) -> None:
        """Moves the case on by a silent, message or timer transition (enabled)."""
        node = case.node
        after = node.after.get(transition.id)
        if after is None:
            after = node.after[transition.id] = self._node(transition.fire(node.marking))
        case.node = after

    # Cases ----------------------------------------------------------------------------

    def _start_case(self) -> None:
        index = self.started_cases
        self.started_cases += 1
        which = index % len(self.variants)
        node = self._node(self.net.initial)
        case = CaseState(index, node, self.roots[which], self.assignments[which], self.now)
        self.open[index] = case
        trigger, self.trigger = self.trigger, None
        self._advance(case)
        self.trigger = trigger

    def _end_case(self, case: CaseState) -> None:
        """The case completed: it is counted and the next case takes its place."""
        self._close(case)
        self.tally.completed(case, self.now)
        case.last = None  # its work items and it form no cycle now: they go when unreferenced
        self._next_case()

    def _stick(self, case: CaseState, why: str, *, replace: bool = True) -> None:
        """The case cannot end: it is reported, its work given up, and (`replace`) the next
        case takes its place."""
        self._close(case)
        self.tally.stuck(case, self.now, why)
        if replace:
            self._next_case()

    def _next_case(self) -> None:
        if self.started_cases < self.scenario.cases:
            self._start_case()

    def _close(self, case: CaseState) -> None:
        """Ends the case: open work withdrawn, running work given up (a step on its cobot runs
        on until it is done, as at run time), holds and interruptions ended."""
        case.ended = True
        del self.open[case.index]
        for item in case.items.values():
            item.withdrawn = True
        for item in list(case.running.values()):
            self._cancel(item)
        case.timers.clear()

    # The firing rule -------------------------------------------------------------------

    def _advance(self, case: CaseState) -> None:
        """Fires what fires by itself, then ends the case, or arms its timers and offers and
        withdraws its work (progress.advance); a case that cannot go on is stuck."""
        try:
            node = case.node
            if node.eager or (node.messages and case.outbox) or case.finished:
                self._fire_all(case)
                node = case.node
            if node.final:
                self._end_case(case)
                return
            if node.timers or case.timers:
                self._arm_timers(case)
            if not self.offer_by_node:
                self._offer_and_withdraw(case)
            elif case.rest is not node:
                # The case's items are its resting node's to_offer: bring them in line.
                diff = node.diffs.get(case.rest)
                self._offers(case, node, diff if diff is not None else node.offers_after(case.rest))
                if node.dead:
                    raise RuntimeFault(
                        f"The case cannot go on: nothing can start in marking "
                        f"{dict(node.marking)} (a guard that holds for no branch?)."
                    )
        except RuntimeFault as fault:
            self._stick(case, str(fault))

    def _fire_all(self, case: CaseState) -> None:
        """Repeats settle → messages → held completions while any of them fires. Where a case
        went from the same node, data and outbox without a choice drawn, work cancelled or a
        completion held, it goes as that case went."""
        key = None
        if not case.finished:
            key = (case.node, case.data, *case.outbox)
            known = self.fired_all.get(key)
            if known is not None:
                case.node, case.data, outbox = known
                case.outbox = [*outbox]
                return
        draws, resets = self.draws, self.resets
        for _ in range(MAX_ROUNDS):
            if case.node.eager:
                self._settle(case)
            node = case.node
            taken = node.messages and case.outbox and self._take_message(case)
            if not (taken or (case.finished and self._complete_held(case))):
                break
        if key is not None and draws == self.draws and resets == self.resets:
            self.fired_all[key] = (case.node, case.data, tuple(case.outbox))

    def _offers(self, case: CaseState, node: Node, diff: Diff) -> None:
        """Withdraws and offers as `diff` says (Node.offers_after), the case now resting at
        `node`."""
        withdrawn, offered = diff
        case.rest = node
        items = case.items
        for task in withdrawn:
            item = items.pop(task, None)  # a started one is running, not withdrawn
            if item is not None:
                item.withdrawn = True
        for task in offered:
            if task in items:
                continue
            resource, profile = case.assigned[task]  # _offer, inline: every task's way in
            items[task] = item = WorkItem(case, profile, resource, self.now, self.trigger)
            if profile.commanded:  # made once per data state: a known one without a call
                item.command = case.data.commands.get(task) or self._command(case, task)
            resource.queue.append(item)
            if not resource.ready:
                resource.ready = True
                (self.ready_machines if resource.machine else self.ready_teams).append(resource)

    def _settle(self, case: CaseState) -> None:
        """Fires silent transitions until none may fire (CaseNet.settle, with the choices of
        prediction.py); what a case reached from the same node and data without drawing a
        choice or cancelling work is taken as it was."""
        key = (case.node, case.data)
        known = self.settled.get(key)
        if known is not None:
            case.node, messages = known
            case.outbox.extend(messages)
            return
        draws, resets = self.draws, self.resets
        sent: list[Message] = []
        fired = 0
        while case.node.eager:
            transition = self._choose(case, case.node)
            if transition is None:
                break
            fired += 1
            if fired > MAX_SILENT_FIRINGS:
                raise RuntimeFault(
                    f"Silent transitions fired {MAX_SILENT_FIRINGS} times in a row "
                    f"(… {transition.id}): a loop whose guards never stop it."
                )
            self._fire(case, transition)
            self._fired(case, transition, sent)
        if draws == self.draws and resets == self.resets:
            self.settled[key] = (case.node, tuple(sent))

    def _choose(self, case: CaseState, node: Node) -> NetTransition | None:
        """The silent transition to fire next (prediction.py, "Choices"); None when none may."""
        weights = self.weights
        first = None
        for transition in node.eager:
            if transition.id in weights or self._guard(case, transition.id):
                first = transition
                break
        if first is None:
            return None
        group = node.competing(self.net, first.id, tuple(t.id for t in node.eager))
        if len(group) == 1:
            return first
        chosen = self._draw(group)
        if chosen is None and not any(t in self.net.guards for t in group):
            self.draws += 1
            chosen = group[int(self.rng.random() * len(group))]
        return self.net.transition(chosen) if chosen is not None else first

    def _draw(self, group: tuple[str, ...]) -> str | None:
        """One of `group` drawn by weight; None when none of them has a weight above 0."""
        weights = self.weights
        total = sum(weights.get(t, 0.0) for t in group)
        if total <= 0:
            return None
        self.draws += 1
        mark = self.rng.random() * total
        for t in group:
            mark -= weights.get(t, 0.0)
            if mark < 0:
                return t
        return next(t for t in reversed(group) if weights.get(t, 0.0) > 0)

    def _guard(self, case: CaseState, transition: str) -> bool:
        if transition not in self.net.guards:
            return True
        data = case.data
        holds = data.guards.get(transition)
        if holds is None:
            holds = data.guards[transition] = self.net.guard_holds(transition, data.values)
        return holds

    def _fired(
        self, case: CaseState, transition: NetTransition, sent: list[Message] | None = None
    ) -> None:
        """After a silent transition fired: the running tasks its `cancels` emptied end, and
        what it sends goes out (and into `sent`)."""
        if transition.resets:
            self.resets += 1
            marking = case.node.marking
            for task, item in list(case.running.items()):
                if not marking.get(f"running:{task}"):
                    self._cancel(item)
        if transition.id in self.net.sends:
            message = self._send(case, transition.id)
            if sent is not None:
                sent.append(message)

    def _send(self, case: CaseState, transition: str) -> Message:
        data = case.data
        message = data.sends.get(transition)
        if message is None:
            sent = outgoing(transition, self.net.sends[transition], data.values, CASE_NAMES)
            message = data.sends[transition] = Message(sent.name, sent.correlation, sent.payload)
        case.outbox.append(message)
        return message

    def _take_message(self, case: CaseState) -> bool:
        """Fires a waiting message transition with the oldest matching message the case sent."""
        for message in case.outbox:
            for transition, config in case.node.messages:
                if config.name != message.name:
                    continue
                data = case.data
                key = (transition, message)
                matches = data.matches.get(key)
                if matches is None:
                    matches = data.matches[key] = correlates(
                        config, data.values, message.correlation, CASE_NAMES
                    )
                if matches:
                    case.outbox.remove(message)
                    fired = self.silent[transition]
                    self._fire(case, fired)
                    after = data.after.get(key)
                    if after is None:
                        after = data.after[key] = self._data({**data.values, **message.payload})
                    case.data = after
                    if fired.resets or transition in self.net.sends:
                        self._fired(case, fired)
                    return True
        return False

    def _arm_timers(self, case: CaseState) -> None:
        enabled = dict(case.node.timers)
        for transition in [t for t in case.timers if t not in enabled]:
            del case.timers[transition]
        for transition, milliseconds in enabled.items():
            if transition not in case.timers:
                due = self.now + milliseconds / 1000 * self.scenario.timer_scale
                case.timers[transition] = due
                heappush(self.heap, (due, next(self.order), None, (case, transition, due)))

    def _ring(self, case: CaseState, transition: str) -> None:
        del case.timers[transition]
        self.trigger = None
        self._fire(case, self.silent[transition])
        try:
            self._fired(case, self.silent[transition])
        except RuntimeFault as fault:
            self._stick(case, str(fault))
            return
        self._advance(case)

    # Offering work -------------------------------------------------------------------

    def _offer_and_withdraw(self, case: CaseState) -> None:
        """The offers of `_advance` worked out case by case, for weighted deferred choices (which
        offer only some of the startable tasks)."""
        node = case.node
        items = case.items
        for task in [t for t in items if t not in node.startable_set]:
            items.pop(task).withdrawn = True
        for task in node.startable:
            if not (task in items or task in case.running or self._chosen_elsewhere(case, task)):
                self._offer(case, task)
        case.rest = node
        if node.dead:
            raise RuntimeFault(
                f"The case cannot go on: nothing can start in marking {dict(node.marking)} "
                "(a guard that holds for no branch?)."
            )

    def _chosen_elsewhere(self, case: CaseState, task: str) -> bool:
        """Whether a weighted deferred choice decides this task's offer: of the startable tasks
        competing for its input, one is offered, drawn by weight (drawn here, once)."""
        node = case.node
        starts = tuple(self.start_ids[t] for t in node.startable)
        group = node.competing(self.net, self.start_ids[task], starts)
        tasks = tuple(t.removeprefix("start:") for t in group)
        if len(tasks) == 1 or not any(t in self.weights for t in tasks):
            return False
        if not any(t in case.items or t in case.running for t in tasks):
            chosen = self._draw(tasks)
            self._offer(case, chosen if chosen is not None else task)
        return True

    def _offer(self, case: CaseState, task: str) -> None:
        if task in case.items:
            return
        resource, profile = case.assigned[task]
        item = WorkItem(case, profile, resource, self.now, self.trigger)
        case.items[task] = item
        if profile.commanded:
            item.command = self._command(case, task)  # the job's, made as it is queued
        resource.queue.append(item)
        if not resource.ready:
            resource.ready = True
            (self.ready_machines if resource.machine else self.ready_teams).append(resource)

    def _command(self, case: CaseState, task: str) -> Mapping[str, Any]:
        """The command of a cobot or device task over the case data (raises RuntimeFault)."""
        data = case.data
        command = data.commands.get(task)
        if command is None:
            command = data.commands[task] = cobot_command(task, self.net.tasks[task], data.values)
        return command

    # Taking work ---------------------------------------------------------------------

    def _dispatch(self) -> None:
        """Lets every cobot, device and team with new work, or newly free, take what it may:
        the cobots and devices first."""
        machines, teams = self.ready_machines, self.ready_teams
        while machines or teams:
            resource = machines.pop(0) if machines else teams.pop(0)
            resource.ready = False
            queue = resource.queue
            if not queue:
                continue
            # The common cases first: the queue's first may go (an item offered and not
            # withdrawn is startable: offers follow the marking), a shared area aside.
            if resource.machine:
                if resource.busy or resource.pauses:
                    continue
                item = queue[0]
                if not (item.withdrawn or resource.holds or item.profile.rules):
                    del queue[0]
                    self._start(item)
                else:
                    self._serve_machine(resource)
            elif (
                len(queue) == 1
                and (resource.people is None or resource.busy < resource.people)
                and not (queue[0].withdrawn or queue[0].profile.rules)
            ):
                self._start(queue.pop())
            else:
                self._serve_team(resource)

    def _serve_team(self, team: Resource) -> None:
        """Free persons take the oldest offered tasks that may start (one kept out of a shared
        area stays offered: the person takes the next)."""
        queue = team.queue
        index = 0
        while index < len(queue) and (team.people is None or team.busy < team.people):
            item = queue[index]
            if item.withdrawn:
                del queue[index]
            elif self._may_start(item):
                del queue[index]
                self._start(item)
            else:
                index += 1

    def _serve_machine(self, machine: Resource) -> None:
        """A free cobot or device takes the first queued step that may start now (jobs.py): none
        while a step runs or a pause holds it, and another case's func hold passes a step by."""
        if machine.busy or machine.pauses:
            return
        queue = machine.queue
        holds = machine.holds
        passed = False
        for index, item in enumerate(queue):
            if item.withdrawn:
                passed = True
            elif holds and any(case is not item.case for case in holds):
                continue
            elif self._may_start(item):
                del queue[index]
                self._start(item)
                break
        if passed:
            machine.queue = [item for item in machine.queue if not item.withdrawn]

    def _may_start(self, item: WorkItem) -> bool:
        """The marking allows its start and no task in a shared area keeps it out."""
        task = item.task
        if task not in item.case.node.startable_set:
            return False
        rules = item.profile.rules
        if rules:
            running = item.case.running
            for rule in rules:
                if rule.keeps_out and rule.held == task and rule.by in running:
                    return False
        return True

    def _start(self, item: WorkItem) -> None:
        case, task, profile = item.case, item.task, item.profile
        node = case.node  # where the case rests: its advance is done
        plan = node.starts.get(task)
        if plan is None:
            plan = node.starts[task] = self._start_plan(node, task)
        after, quiet = plan
        case.node = after
        del case.items[task]
        case.running[task] = item
        now = item.started = self.now
        resource = item.resource
        resource.busy += 1
        resource.work_items += 1
        if now > item.offered:
            resource.waiting_seconds += now - item.offered
            resource.waited += 1
            profile.counts[2] += now - item.offered
        work = profile.fixed
        if work is None:
            work = profile.sample() if profile.sample is not None else self._work(item)
        item.work = work
        self.trigger = item
        if self.trace_on:
            self.tally.trace.append(TraceEvent(case.index, now, "start", task))
        if not profile.rules:
            heappush(self.heap, (now + self.handover + work, next(self.order), item, 0))
        elif self.handover:
            item.entered = False
            heappush(self.heap, (now + self.handover, next(self.order), item, ENTERS))
        else:
            self._enter(item)
        case.tasks_run += 1
        if case.tasks_run > self.max_tasks:
            self._stick(case, f"The case ran {case.tasks_run - 1} tasks without ending: a loop whose choices never leave it (give the choice weights?).")  # fmt: skip
        elif quiet and not (case.finished or case.timers):
            case.rest = after
        else:
            self._advance(case)

    def _start_plan(self, node: Node, task: str) -> tuple[Node, bool]:
        """The node after starting `task` at `node`, and whether that is all there is to it."""
        after = self._node(self.net.start(node.marking, task))
        withdrawn, offered = after.offers_after(node)
        quiet = self.offer_by_node and after.calm and not offered and withdrawn in ((), (task,))
        return after, quiet

    def _work(self, item: WorkItem) -> float:
        """The plant's time for a task given none (at full speed), else the default's."""
        assert self.plant is not None
        seconds = self.plant.seconds(item.resource.key, item.command, self.now + self.handover)
        if seconds is None:
            return self.scenario.cobot_default.sample(self.rng)
        seconds = float(seconds)
        return 0.0 if seconds < 0.0 else seconds  # max(seconds, 0.0) without the call

    # Space constraints -----------------------------------------------------------------

    def _enter(self, item: WorkItem) -> None:
        """A space constraint's task begins its work, in its area: the steps it shares the area
        with that have entered theirs are paused or slowed, or it is (those entering later
        interrupt it as they enter). A step cancelled meanwhile runs on, out of the rules."""
        item.entered = True
        item.remaining, item.since, item.pauses, item.slows = item.work, self.now, 0, 0
        heappush(self.heap, (self.now + item.work, next(self.order), item, item.version))
        if not item.withdrawn:
            self._interrupt(item)

    def _interrupt(self, entering: WorkItem) -> None:
        """Pauses or slows the steps the entering task shares an area with, or itself (a step
        starting slowly beside an operator), as progress._interrupt_shared_space does."""
        case, task = entering.case, entering.task
        for rule in entering.profile.rules:
            if rule.keeps_out:
                continue
            other = case.running.get(rule.by if rule.held == task else rule.held)
            if other is None or not other.entered:
                continue
            held, by = (entering, other) if rule.held == task else (other, entering)
            if held.profile.kind != "cobot":
                continue  # only a cobot's step is paused or slowed
            case.interruptions.append((held, by, rule.mode))
            if rule.mode == "pause":
                held.pauses += 1
                held.resource.pauses += 1
            else:
                held.slows += 1
            self._set_rate(held)

    def _end_interruptions(self, item: WorkItem) -> None:
        """Ends the interruptions `item` suffered or caused (it completed or was cancelled): a
        paused or slowed step goes on at full speed unless another still holds it."""
        case = item.case
        ended = [i for i in case.interruptions if item is i[0] or item is i[1]]
        if not ended:
            return
        case.interruptions = [i for i in case.interruptions if i not in ended]
        for held, _, mode in ended:
            if mode == "pause":
                held.pauses -= 1
                held.resource.pauses -= 1
            else:
                held.slows -= 1
            self._set_rate(held)
            self._wake(held.resource)

    def _set_rate(self, item: WorkItem) -> None:
        """Its work goes on at the rate its interruptions leave it: 0 paused, slow, or full."""
        rate = 0.0 if item.pauses else (self.scenario.slow_rate if item.slows else 1.0)
        if rate == item.rate or item.done:
            return
        elapsed = self.now - item.since
        item.remaining = max(item.remaining - elapsed * item.rate, 0.0)
        if item.rate < 1:
            item.resource.interrupted_seconds += elapsed
        item.since, item.rate = self.now, rate
        item.version += 1  # its end on the heap is no longer its end
        self._schedule(item)

    # Ending work ------------------------------------------------------------------------

    def _work_done(self, item: WorkItem) -> None:
        """A person's or a cobot's work on the item is done: it completes, unless a func
        constraint holds it (then it completes as soon as the constraint allows)."""
        case, resource, task = item.case, item.resource, item.task
        item.done = True
        if item.rate < 1:
            resource.interrupted_seconds += self.now - item.since
        if resource.machine:
            resource.busy -= 1
            resource.busy_seconds += self.now - item.started
            if resource.queue and not resource.ready:
                resource.ready = True
                self.ready_machines.append(resource)
        if case.ended or item.withdrawn:
            return
        self.trigger = item
        node = case.node
        plan = node.completes.get(task)
        if plan is None:
            if not node.can_complete(self.net, task):
                case.finished.append(item)
                if resource.kind == "cobot":  # it holds the part (a device call holds nothing)
                    self._hold(resource, case, +1)
                self._advance(case)
                return
            plan = node.completes[task] = self._complete_plan(node, task)
        after, diff, single = plan
        try:
            self._complete(item, after)
            # The offers raise too: a step's command is made as it is offered.
            if diff is None or case.finished or case.timers:
                self._advance(case)
            elif single is not None and not (self.ready_machines or self.ready_teams):
                self._offer_one(case, after, single)
            else:
                self._offers(case, after, diff)
        except RuntimeFault as fault:
            self._stick(case, str(fault))

    def _offer_one(self, case: CaseState, node: Node, task: str) -> None:
        """`_offers` for one task offered, nothing withdrawn and no one else to serve: what
        `_dispatch` would do then, done at once when its cobot or team may take it now."""
        resource, profile = case.assigned[task]
        if (
            resource.queue
            or profile.rules
            or resource.busy == resource.people  # a cobot's or device's: 1, busy 0 or 1
            or resource.pauses
            or resource.holds
        ):
            self._offers(case, node, ((), (task,)))
            return
        case.rest = node
        case.items[task] = item = WorkItem(case, profile, resource, self.now, self.trigger)
        if profile.commanded:  # as in _offers
            item.command = case.data.commands.get(task) or self._command(case, task)
        self._start(item)

    def _complete_plan(self, node: Node, task: str) -> CompletionPlan:
        """The node after completing `task` at `node` (enabled), the offers that change then
        when nothing else follows (None: an advance does the rest), and the one task offered
        when that is all they do (None: none, or more, or a withdrawal too)."""
        after = self._node(self.net.complete(node.marking, task))
        if not (self.offer_by_node and after.calm):
            return after, None, None
        diff = after.offers_after(node)
        withdrawn, offered = diff
        return after, diff, offered[0] if len(offered) == 1 and not withdrawn else None

    def _complete_held(self, case: CaseState) -> bool:
        node = case.node
        for item in case.finished:
            if node.can_complete(self.net, item.task):
                plan = node.completes.get(item.task)
                if plan is None:
                    plan = node.completes[item.task] = self._complete_plan(node, item.task)
                self._complete(item, plan[0])
                return True
        return False

    def _complete(self, item: WorkItem, after: Node) -> None:
        """Completes the item, the case moving to `after`: its outputs into the case data, what
        it sends, the interruptions it caused or suffered end. Raises RuntimeFault when an
        output fails (at run time: an incident, the case waits for a person)."""
        case, task, profile = item.case, item.task, item.profile
        if profile.changes_data:
            case.data = self._outputs(item)
        case.node = after
        del case.running[task]
        now = item.completed = self.now
        resource = item.resource
        if not resource.machine:
            resource.busy -= 1
            resource.busy_seconds += now - item.started
            if resource.queue and not resource.ready:
                resource.ready = True
                self.ready_teams.append(resource)
        if case.finished and item in case.finished:
            self._release_hold(item)
        if self.trigger is not item:
            item.released_by = self.trigger
        case.last = item
        counts = profile.counts
        counts[0] += 1
        counts[1] += now - item.started
        if case.interruptions:
            self._end_interruptions(item)
        if profile.watched:
            if self.trace_on:
                self.tally.trace.append(TraceEvent(case.index, now, "complete", task))
            if task in self.net.sends:
                self._send(case, task)
            if profile.rules:  # what it kept out of the area may start now
                for waiting in (*self.machines, *self.teams):
                    if waiting.queue:
                        self._wake(waiting)

    def _release_hold(self, item: WorkItem) -> None:
        """The item, done, no longer waits for a func constraint; its cobot holds nothing for it."""
        item.case.finished.remove(item)
        if item.resource.kind == "cobot":
            self._hold(item.resource, item.case, -1)

    def _hold(self, machine: Resource, case: CaseState, change: int) -> None:
        holds = machine.holds
        if not holds:
            machine.held_since = self.now
        count = holds.get(case, 0) + change
        if count:
            holds[case] = count
        else:
            del holds[case]
            self._wake(machine)
        if not holds:
            machine.held_seconds += self.now - machine.held_since

    def _cancel(self, item: WorkItem) -> None:
        """Ends a running item its case gave up (a `cancels`, or the case ended): its person
        stops (and leaves the area); a step on its cobot runs on until it is done."""
        case, resource = item.case, item.resource
        del case.running[item.task]
        item.withdrawn = True
        if not resource.machine:
            resource.busy -= 1
            resource.busy_seconds += self.now - item.started
            self._wake(resource)
        if item in case.finished:
            self._release_hold(item)
        if case.interruptions:
            self._end_interruptions(item)

    def _outputs(self, item: WorkItem) -> DataState:
        """The case data after the item's result (runtime.apply_outputs), computed once per data
        state and result. Raises RuntimeFault when an output fails."""
        case, task = item.case, item.task
        config = self.net.tasks[task]
        kind = item.profile.kind
        result: Mapping[str, Any]
        if kind == "operator":
            nth = case.answers.get(task, 0)
            case.answers[task] = nth + 1
            key: Any = (task, nth % self.periods[task])
            answer = self.answers.get(key)
            if answer is None:
                answer = self.answers[key] = example_answers(config.form, nth)
            result = answer
        elif kind == "cobot":
            seconds = round(item.work, 3)  # at full speed: the program's time
            key, result = (task, seconds), {"outcome": "ran", "seconds": seconds}
        else:
            result = self._device_answer(item)
            key = (task, _frozen(result))
        data = case.data
        after = data.after.get(key)
        if after is None:
            after = data.after[key] = self._data(apply_outputs(config, task, result, data.values))
        return after

    def _device_answer(self, item: WorkItem) -> dict[str, Any]:
        """The plant's answer to the item's device call, else its happy answer: a gesture seen,
        a face authorised, every screw expected found, the place free, an inspection "ok"."""
        device = self.net.tasks[item.task].device
        assert device is not None
        answer = None
        if self.plant is not None:
            answer = self.plant.answer(item.resource.key, item.command, self.rng, self.now)
        if answer is None:
            arguments = dict(zip(device.argument_names, item.command["args"], strict=True))
            answer = {
                name: arguments.get("expected", 0) if name == "found" else HAPPY_OUTPUTS.get(name)
                for name in device.output_names
            }
        return dict(answer)


def _kind(config: TaskConfig) -> str:
    """operator, cobot (a program step) or device (a device call, whoever's actor makes it)."""
    if config.kind == "operator":
        return "operator"
    return "device" if config.device is not None else "cobot"


def _changes_data(config: TaskConfig) -> bool:
    """Whether a completion may change the case data: outputs to map, or a result that is
    stored whole (an operator's form answers, a step's outcome, a device call's outputs)."""
    if config.outputs is not None:
        return bool(config.outputs)
    if config.kind == "operator":
        return bool(config.form and config.form.get("required"))
    if config.device is not None:
        return bool(config.device.output_names)
    return True


def _frozen(value: Any) -> Any:
    """A JSON value as something hashable, equal for equal values (true, 1 and 1.0 are three:
    Python's == says one)."""
    if isinstance(value, Mapping):
        return tuple(sorted((key, _frozen(v)) for key, v in value.items()))
    if isinstance(value, list | tuple):
        return tuple(_frozen(v) for v in value)
    return (type(value), value)
