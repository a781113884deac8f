"""The Petri net pieces each BPMN flow node becomes, after Dijkman, Dumas and Ouyang's figure 3.

`bpmn.py` and `bpmn_scopes.py` read the file into flow nodes, sequence flows
and scopes (the process, each sub-process and each activity with boundary
events), refusing what is not mapped; `FlowNet` builds one process' places,
transitions and arcs from them. The mapping is described in `bpmn.py`'s
docstring.
"""

from collections.abc import Callable
from dataclasses import dataclass, field
from itertools import combinations
from typing import Any

Json = dict[str, Any]

TASK_KINDS = frozenset(
    {
        "task",
        "userTask",
        "manualTask",
        "serviceTask",
        "scriptTask",
        "businessRuleTask",
        "sendTask",
        "receiveTask",
    }
)
GATEWAY_KINDS = frozenset(
    {"parallelGateway", "exclusiveGateway", "eventBasedGateway", "inclusiveGateway"}
)
EVENT_KINDS = frozenset(
    {"startEvent", "endEvent", "intermediateThrowEvent", "intermediateCatchEvent", "boundaryEvent"}
)
STEP_KINDS = frozenset({"begin", "finish"})
"""The silent steps a scope's boundaries become: `<name>: begins` and `<name>: ends`."""
KIND_WORDS = {
    "startEvent": "start event",
    "endEvent": "end event",
    "intermediateThrowEvent": "intermediate event",
    "intermediateCatchEvent": "intermediate event",
    "boundaryEvent": "boundary event",
    "parallelGateway": "parallel gateway",
    "exclusiveGateway": "exclusive gateway",
    "inclusiveGateway": "inclusive gateway",
    "eventBasedGateway": "event-based gateway",
    "complexGateway": "complex gateway",
    "subProcess": "sub-process",
    "eventSubProcess": "event sub-process",
    "adHocSubProcess": "ad-hoc sub-process",
    "callActivity": "call activity",
    "userTask": "user task",
    "manualTask": "manual task",
    "serviceTask": "service task",
    "scriptTask": "script task",
    "businessRuleTask": "business rule task",
    "sendTask": "send task",
    "receiveTask": "receive task",
    "sequenceFlow": "sequence flow",
    "messageFlow": "message flow",
}
MAX_INCLUSIVE_BRANCHES = 4
"""An inclusive split gets a transition per non-empty subset of its branches: 15 at 4."""


def describe(kind: str, xml_id: str, name: str | None) -> str:
    """How a refusal names an element: `task "Check order" (sid-89...)`, or `task sid-89...`."""
    word = KIND_WORDS.get(kind, kind)
    return f'{word} "{name}" ({xml_id})' if name else f"{word} {xml_id}"


@dataclass(eq=False)
class Scope:
    """The process, a sub-process, or an activity with boundary events: what a cancel empties."""

    hrc_id: str
    parent: "Scope | None"
    source: str
    """The place its start events take their token from."""
    sink: str
    """The place its end events put their token in."""
    place: str | None = None
    """Marked from its begin to its end step; boundary events consume it. None for a process."""
    armed: list[str] = field(default_factory=list)
    """One place per non-interrupting boundary event: it fires at most once per activation."""
    members: list[str] = field(default_factory=list)
    """Every place and task inside it, nested scopes' included."""

    def chain(self) -> list["Scope"]:
        scopes: list[Scope] = []
        scope: Scope | None = self
        while scope is not None:
            scopes.append(scope)
            scope = scope.parent
        return scopes

    def process(self) -> "Scope":
        return self.chain()[-1]


@dataclass(eq=False)
class FlowNode:
    """An event, task, gateway or scope step, with the flows that touch it."""

    kind: str
    """The BPMN element's local name (`task`, `exclusiveGateway`, ...), or `begin`/`finish`."""
    xml_id: str
    hrc_id: str
    name: str | None
    extra: Json
    """Its `<hrc:extra>`, and the hrc-pattern keys the reader derived (`message`, `timer`, ...)."""
    scope: Scope
    default: str | None = None
    """A gateway's default flow."""
    incoming: list["Flow"] = field(default_factory=list)
    outgoing: list["Flow"] = field(default_factory=list)
    pre: list[str] = field(default_factory=list)
    """Places its transition consumes besides its incoming flows'."""
    post: list[str] = field(default_factory=list)
    """Places its transition marks besides its outgoing flows'."""
    cancels: list[Scope] = field(default_factory=list)
    """Scopes whose places and tasks its transition empties."""
    cancels_places: list[str] = field(default_factory=list)
    post_flows: list["Flow"] = field(default_factory=list)
    """Flows its transition marks besides its own: an error thrown to a boundary event's."""
    routed: bool = False
    loop_head: "FlowNode | None" = None
    """A looping scope's begin step, on its end step: the loop goes back there."""
    to_sink: "Scope | None" = None
    """A scope (the process) whose sink its transition marks, not its own scope's."""
    """An end event whose token goes to a boundary event's flows, not to its scope's end."""
    keys: Json = field(default_factory=dict)
    """The hrc-pattern keys the reader derived for its transition (`message`, `timer`, ...)."""
    receive: Json | None = None
    """A message a task waits for: a silent message transition in front of it."""
    loop: Json | None = None
    """A standard loop: `{"guard": ...}` or `{"rewrite": ...}` on the step back."""
    writes: list[str] = field(default_factory=list)
    """A task's data outputs and the data objects it writes, by name."""
    copies: tuple[int, bool] = (1, False)
    """Multi-instance: (how many, in sequence)."""
    inclusive_join: "FlowNode | None" = None
    """An inclusive split's matching join, once found."""
    branch_flows: dict[str, str] = field(default_factory=dict)
    """An inclusive split's outgoing flow -> the join's incoming flow its branch reaches."""

    def describe(self) -> str:
        return describe(self.kind, self.xml_id, self.name)


@dataclass(eq=False)
class Flow:
    """A sequence flow, which becomes a place."""

    xml_id: str
    place: str
    """The id of the place this flow becomes (flows into one event-based gateway share one)."""
    source: FlowNode
    target: FlowNode
    extra: Json
    scope: Scope
    guard: str | None = None
    """Its condition in hrc's language."""
    rewrite: str | None = None
    """Its condition when it did not translate."""


class FlowNet:
    """The places, transitions and arcs one process' flow nodes become."""

    def __init__(self, fresh: Callable[[str], str], process_id: str, flows: list[Flow]) -> None:
        self.fresh = fresh
        """Makes an id no element has from a base, as `base` or `base_2`, ..."""
        self.process_id = process_id
        self.places: list[Json] = []
        self.place_by_id: dict[str, Json] = {}
        for flow in flows:
            if flow.place not in self.place_by_id:
                self.place(flow.place, flow.scope, **flow.extra)
        self.transitions: list[Json] = []
        self.arcs: list[list[str]] = []
        self.cancelling: list[tuple[Json, FlowNode]] = []
        self.loop_inputs: dict[int, str] = {}
        """id() of a looping scope's begin step -> the place its loop comes back to."""

    def transition(
        self,
        transition_id: str,
        scope: Scope,
        *,
        performer: str | None = None,
        label: str | None = None,
        guard: str | None = None,
        extra: Json | None = None,
    ) -> str:
        data: Json = {"id": transition_id}
        if performer is not None:
            data["performer"] = performer
        if label:
            data["label"] = label
        if guard is not None:
            data["guard"] = guard
        self.transitions.append({**data, **(extra or {})})
        if performer is not None:
            for enclosing in scope.chain():
                enclosing.members.append(transition_id)
        return transition_id

    def place(self, place_id: str, scope: Scope, **data: Any) -> str:
        place = {"id": place_id, **data}
        if place_id not in self.place_by_id:
            self.places.append(place)
            self.place_by_id[place_id] = place
            for enclosing in scope.chain():
                enclosing.members.append(place_id)
        return place_id

    def arc(self, source: str, target: str) -> None:
        self.arcs.append([source, target])

    def add(self, node: FlowNode, performer: str | None) -> None:
        if node.kind == "parallelGateway":
            step = self._step(
                node, node.hrc_id, label=node.name, extra={**node.keys, **_without_id(node.extra)}
            )
            for flow in node.incoming:
                self.arc(flow.place, step)
            for flow in node.outgoing:
                self.arc(step, flow.place)
        elif node.kind in ("exclusiveGateway", "eventBasedGateway"):
            self._exclusive(node)
        elif node.kind == "inclusiveGateway":
            self._inclusive(node)
        elif node.kind not in ("startEvent", "endEvent", "caughtBoundaryEvent", "unreached"):
            self._activity(node, performer)

    def _step(
        self,
        node: FlowNode,
        step_id: str,
        *,
        performer: str | None = None,
        label: str | None = None,
        guard: str | None = None,
        extra: Json | None = None,
    ) -> str:
        """A transition of the node, with its extra places and its cancellations."""
        self.transition(
            step_id, node.scope, performer=performer, label=label, guard=guard, extra=extra
        )
        for place in node.pre:
            self.arc(place, step_id)
        for place in node.post:
            self.arc(step_id, place)
        for flow in node.post_flows:
            self.arc(step_id, flow.place)
        if node.to_sink is not None:
            self.arc(step_id, node.to_sink.sink)
        if node.cancels or node.cancels_places:
            self.cancelling.append((self.transitions[-1], node))
        return step_id

    def finish(self) -> None:
        """Writes every `cancels` list, now that every scope knows its members."""
        for transition, node in self.cancelling:
            ids = [*node.cancels_places]
            for scope in node.cancels:
                ids += scope.members
            consumed = set(node.pre)
            cancels = [i for i in dict.fromkeys(ids) if i not in consumed or i in node.post]
            if cancels:
                transition["cancels"] = cancels

    def _merged_input(self, node: FlowNode) -> str | None:
        """The one place the node's transition consumes: several incoming flows merge first.

        A receive task's message step comes before it and takes that place
        itself, so after an event-based gateway it races like a catch event.
        """
        merged: str | None = None
        if len(node.incoming) == 1 and not node.loop:
            merged = node.incoming[0].place
        elif node.incoming or node.loop:
            merged = self.place(self.fresh(f"{node.hrc_id}_in"), node.scope)
            for flow in node.incoming:
                step = self.transition(self.fresh(f"{node.hrc_id}_{flow.xml_id}"), node.scope)
                self.arc(flow.place, step)
                self.arc(step, merged)
        if node.receive is None:
            return merged
        received = self.place(self.fresh(f"{node.hrc_id}_received"), node.scope)
        step = self.transition(
            self.fresh(f"{node.hrc_id}_receive"),
            node.scope,
            label=f"{node.name or node.hrc_id}: message",
            extra={"message": node.receive},
        )
        for place in [merged] if merged is not None else node.pre:
            self.arc(place, step)
        if merged is None:
            node.pre = []  # a task in a scope of its own: the message step takes its input
        self.arc(step, received)
        return received

    def _activity(self, node: FlowNode, performer: str | None) -> None:
        extra = {**node.keys, **_without_id(node.extra)}
        if node.kind in TASK_KINDS and node.kind != "task":
            extra = {"bpmn": node.kind, **extra}
        label = node.name
        if node.kind == "begin":
            label = f"{node.name or node.xml_id}: begins"
        elif node.kind == "finish":
            label = f"{node.name or node.xml_id}: ends"
        into = self._merged_input(node)
        count, sequential = node.copies
        if count > 1:
            after = self._copies(node, into, performer, count, sequential, extra)
        else:
            after = self._step(node, node.hrc_id, performer=performer, label=label, extra=extra)
            if into is not None:
                self.arc(into, after)
        if node.loop is not None and into is not None:
            if node.kind == "begin":
                self.loop_inputs[id(node)] = into
            else:
                after = self._loop(node, into, after)
        head = node.loop_head
        if head is not None and id(head) in self.loop_inputs:
            after = self._loop(head, self.loop_inputs[id(head)], after)
        # Several flows out of an activity all get a token: a parallel split, no step needed.
        for flow in node.outgoing:
            self.arc(after, flow.place)

    def _loop(self, node: FlowNode, into: str, last: str) -> str:
        """A standard loop: after the activity, a step back to its input or one out; returns it."""
        loop = node.loop or {}
        done = self.place(self.fresh(f"{node.hrc_id}_done"), node.scope)
        self.arc(last, done)
        back = self.transition(
            self.fresh(f"{node.hrc_id}_again"),
            node.scope,
            label=f"{node.name or node.hrc_id}: again",
            extra=loop,
        )
        self.arc(done, back)
        self.arc(back, into)
        guard = loop.get("guard")
        leave = self.transition(
            self.fresh(f"{node.hrc_id}_exit"),
            node.scope,
            guard=f"not ({guard})" if guard else None,
        )
        self.arc(done, leave)
        return leave

    def _copies(
        self,
        node: FlowNode,
        into: str | None,
        performer: str | None,
        count: int,
        sequential: bool,
        extra: Json,
    ) -> str:
        """A multi-instance task's copies, one after the other or side by side; returns the exit."""
        ids = [node.hrc_id] + [self.fresh(f"{node.hrc_id}_{n}") for n in range(2, count + 1)]
        labels = [f"{node.name or node.hrc_id} ({n} of {count})" for n in range(1, count + 1)]
        exit_step = self._step(node, self.fresh(f"{node.hrc_id}_all_done"))
        if sequential:
            before = into
            for copy, label in zip(ids, labels, strict=True):
                self.transition(copy, node.scope, performer=performer, label=label, extra=extra)
                if before is not None:
                    self.arc(before, copy)
                before = self.place(self.fresh(f"{copy}_done"), node.scope)
                self.arc(copy, before)
            self.arc(before or "", exit_step)
            return exit_step
        split = self.transition(self.fresh(f"{node.hrc_id}_split"), node.scope)
        if into is not None:
            self.arc(into, split)
        for copy, label in zip(ids, labels, strict=True):
            ready = self.place(self.fresh(f"{copy}_ready"), node.scope)
            done = self.place(self.fresh(f"{copy}_done"), node.scope)
            self.transition(copy, node.scope, performer=performer, label=label, extra=extra)
            self.arc(split, ready)
            self.arc(ready, copy)
            self.arc(copy, done)
            self.arc(done, exit_step)
        return exit_step

    def _exclusive(self, node: FlowNode) -> None:
        """A place where the choice or merge is made, and a silent transition per branch.

        An event-based gateway's branches share that place: the events after it
        consume it, so the first to happen takes the token (a deferred choice).
        """
        incoming, outgoing = node.incoming, node.outgoing
        extra = _without_id(node.extra)
        deferred = node.kind == "eventBasedGateway"
        if len(incoming) == 1:  # a split (or a pass): the incoming flow's place chooses
            centre, merge, split = incoming[0].place, False, True
        elif len(outgoing) == 1 and not deferred:
            centre, merge, split = outgoing[0].place, True, False
        else:
            centre, merge, split = node.hrc_id, True, True
            self.place(centre, node.scope, **({"name": node.name} if node.name else {}))
        # The gateway's own data goes with the place that stands for it.
        self.place_by_id[centre].update(extra)
        if merge:
            for flow in incoming:
                step = self.transition(self.fresh(f"{node.hrc_id}_{flow.xml_id}"), node.scope)
                self.arc(flow.place, step)
                self.arc(step, centre)
        if deferred:
            for flow in outgoing:
                flow.place = centre
            return
        if split:
            guards = self._guards(node)
            for flow in _unguarded_towards_the_end(outgoing, guards):
                step = self.transition(
                    self.fresh(f"{node.hrc_id}_{flow.xml_id}"),
                    node.scope,
                    guard=guards.get(flow.xml_id),
                    extra={"rewrite": flow.rewrite} if flow.rewrite else None,
                )
                self.arc(centre, step)
                self.arc(step, flow.place)

    def _guards(self, node: FlowNode) -> dict[str, str]:
        """Each outgoing flow's guard; the default flow's is that none of the others holds."""
        guards = {f.xml_id: f.guard for f in node.outgoing if f.guard is not None}
        default = node.default
        others = [g for f, g in guards.items() if f != default]
        if default and others and len(others) == len(node.outgoing) - 1:
            guards[default] = " and ".join(f"not ({g})" for g in others)
        return guards

    def _inclusive(self, node: FlowNode) -> None:
        """An inclusive split: a transition per non-empty subset of its branches.

        Each also marks a place that tells the matching join which branches to
        wait for; the join has a transition per subset consuming that place and
        the subset's incoming flows. A split whose branches never meet again
        needs no such place.
        """
        if len(node.outgoing) <= 1:
            if len(node.incoming) > 1 and node.inclusive_join is None:
                return  # a join: built by its split
            self._exclusive(node)
            return
        into = self._merged_input(node)
        join = node.inclusive_join
        guards = {f.xml_id: f.guard for f in node.outgoing}
        rewrites = [f.rewrite for f in node.outgoing if f.rewrite]
        default = node.default
        for size in range(1, len(node.outgoing) + 1):
            for subset in combinations(node.outgoing, size):
                chosen = {f.xml_id for f in subset}
                if default in chosen and size > 1:
                    continue  # the default flow is taken alone, when no other holds
                guard = _subset_guard(guards, chosen, default)
                step = self.transition(
                    self.fresh(f"{node.hrc_id}_{'_'.join(f.xml_id for f in subset)}"),
                    node.scope,
                    guard=guard,
                    extra={"rewrite": "; ".join(rewrites)} if rewrites else None,
                )
                if into is not None:
                    self.arc(into, step)
                for flow in subset:
                    self.arc(step, flow.place)
                if join is None:
                    continue
                chosen_place = self.place(self.fresh(f"{step}_chosen"), node.scope)
                self.arc(step, chosen_place)
                joined = self.transition(self.fresh(f"{join.hrc_id}_{step}"), join.scope)
                self.arc(chosen_place, joined)
                for flow in subset:
                    self.arc(node.branch_flows[flow.xml_id], joined)
                for flow in join.outgoing:
                    self.arc(joined, flow.place)

    def ends(self, events: list[FlowNode], scope: Scope, *, start: bool) -> None:
        """The steps from the scope's source place (start=True), or into its sink place.

        Each start event is a silent transition from the source place into its
        outgoing flows (a message start fed by a message flow waits for it
        there); each flow into an end event ends through a silent transition.
        One event of its kind is the place itself (the reader names the place
        after it) and its step gets a fresh id; with several, each step is the
        event (their own hrc:extra, which would describe a place, is then not read).
        """
        shared = len(events) > 1
        for event in events:
            extra = {**event.keys, **(_without_id(event.extra) if shared else {})}
            if start:
                step_id = event.hrc_id if shared else self.fresh(f"{event.hrc_id}_start")
                step = self._step(event, step_id, label=event.name if shared else None, extra=extra)
                self.arc(scope.source, step)
                for flow in event.outgoing:
                    self.arc(step, flow.place)
                continue
            # Each flow into an end event ends there on its own (the event merges them).
            for flow in event.incoming:
                if shared and len(event.incoming) == 1:
                    step_id, label = event.hrc_id, event.name
                elif len(event.incoming) == 1:
                    step_id, label = self.fresh(f"{event.hrc_id}_end"), None
                else:
                    step_id, label = self.fresh(f"{event.hrc_id}_{flow.xml_id}"), None
                step = self._step(event, step_id, label=label, extra=extra)
                self.arc(flow.place, step)
                if not event.post and not event.routed and event.to_sink is None:
                    self.arc(step, scope.sink)


def _subset_guard(
    guards: dict[str, str | None], chosen: set[str], default: str | None
) -> str | None:
    """The guard of taking exactly the chosen branches of an inclusive split."""
    parts = []
    for flow_id, guard in guards.items():
        if flow_id == default:
            continue
        if guard is not None:
            parts.append(f"({guard})" if flow_id in chosen else f"not ({guard})")
    return " and ".join(parts) or None


def _without_id(extra: Json) -> Json:
    return {key: value for key, value in extra.items() if key != "id"}


def _unguarded_towards_the_end(flows: list[Flow], guards: dict[str, str]) -> list[Flow]:
    """A split's flows in net order, those without a condition reordered nearest an end first.

    The runtime takes the first branch whose guard holds, and a branch without one always
    holds. BPMN leaves the choice between unconditioned flows open, but a model whose first
    such flow goes back (a "Retry?" whose "Yes" is drawn first, a process-mining model's loop)
    would then never end; taking the branch with the fewest steps left to an end keeps each
    choice moving towards completion, and the loop stays for a guard to take.
    """
    unguarded = [flow for flow in flows if flow.xml_id not in guards]
    ordered = iter(sorted(unguarded, key=lambda flow: _steps_to_an_end(flow.target)))
    return [next(ordered) if flow.xml_id not in guards else flow for flow in flows]


def _steps_to_an_end(start: FlowNode) -> float:
    """The fewest sequence flows from `start` to a node no flow leaves (an end of its scope)."""
    seen = {id(start)}
    frontier, steps = [start], 0
    while frontier:
        if any(not node.outgoing for node in frontier):
            return steps
        following = []
        for node in frontier:
            for flow in node.outgoing:
                if id(flow.target) not in seen:
                    seen.add(id(flow.target))
                    following.append(flow.target)
        frontier, steps = following, steps + 1
    return float("inf")
