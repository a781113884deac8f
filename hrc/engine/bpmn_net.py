"""The Petri net pieces each BPMN flow node becomes, after Dijkman, Dumas and Ouyang's figure 3.

`bpmn.py` reads the file and refuses what is not mapped; `FlowNet` builds one
process' places, transitions and arcs from the flow nodes and sequence flows
it found. The mapping is described in `bpmn.py`'s docstring.
"""

from collections.abc import Callable
from dataclasses import dataclass, field
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
GATEWAY_KINDS = frozenset({"parallelGateway", "exclusiveGateway"})
EVENT_KINDS = frozenset(
    {"startEvent", "endEvent", "intermediateThrowEvent", "intermediateCatchEvent"}
)
KIND_WORDS = {
    "startEvent": "start event",
    "endEvent": "end event",
    "intermediateThrowEvent": "intermediate event",
    "intermediateCatchEvent": "intermediate event",
    "parallelGateway": "parallel gateway",
    "exclusiveGateway": "exclusive gateway",
}


@dataclass
class FlowNode:
    """An event, task or gateway of a process, with the flows that touch it."""

    kind: str
    """The BPMN element's local name: `task`, `exclusiveGateway`, ..."""
    xml_id: str
    hrc_id: str
    name: str | None
    extra: Json
    """Its `<hrc:extra>`."""
    default: str | None = None
    """An exclusive gateway's default flow."""
    incoming: list["Flow"] = field(default_factory=list)
    outgoing: list["Flow"] = field(default_factory=list)

    def describe(self) -> str:
        return f"{KIND_WORDS.get(self.kind, self.kind)} {self.xml_id}"


@dataclass
class Flow:
    """A sequence flow, which becomes a place."""

    xml_id: str
    place: str
    """The id of the place this flow becomes."""
    source: FlowNode
    target: FlowNode
    extra: Json
    condition: str | None = None
    """The text of its conditionExpression, which becomes a guard."""


class FlowNet:
    """The places, transitions and arcs one process' flow nodes become."""

    def __init__(self, fresh: Callable[[str], str], process_id: str, flows: list[Flow]) -> None:
        self.fresh = fresh
        """Makes an id no element has from a base, as `base` or `base_2`, ..."""
        self.process_id = process_id
        self.places: list[Json] = [{"id": flow.place, **flow.extra} for flow in flows]
        self.place_by_id = {place["id"]: place for place in self.places}
        self.transitions: list[Json] = []
        self.arcs: list[list[str]] = []

    def transition(
        self,
        transition_id: str,
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
        return transition_id

    def place(self, place_id: str, **data: Any) -> str:
        place = {"id": place_id, **data}
        self.places.append(place)
        self.place_by_id.setdefault(place_id, place)
        return place_id

    def arc(self, source: str, target: str) -> None:
        self.arcs.append([source, target])

    def add(self, node: FlowNode, performer: str | None) -> None:
        if node.kind in TASK_KINDS or node.kind.startswith("intermediate"):
            self._activity(node, performer)
        elif node.kind == "parallelGateway":
            self.transition(node.hrc_id, label=node.name, extra=_without_id(node.extra))
            for flow in node.incoming:
                self.arc(flow.place, node.hrc_id)
            for flow in node.outgoing:
                self.arc(node.hrc_id, flow.place)
        elif node.kind == "exclusiveGateway":
            self._exclusive(node)

    def _activity(self, node: FlowNode, performer: str | None) -> None:
        extra = _without_id(node.extra)
        if node.kind in TASK_KINDS and node.kind != "task":
            extra = {"bpmn": node.kind, **extra}
        self.transition(node.hrc_id, performer=performer, label=node.name, extra=extra)
        if len(node.incoming) > 1:
            # Several flows into an activity merge first (Dijkman et al.'s normalisation).
            merged = self.place(self.fresh(f"{node.hrc_id}_in"))
            for flow in node.incoming:
                step = self.transition(self.fresh(f"{node.hrc_id}_{flow.xml_id}"))
                self.arc(flow.place, step)
                self.arc(step, merged)
            self.arc(merged, node.hrc_id)
        else:
            for flow in node.incoming:
                self.arc(flow.place, node.hrc_id)
        # Several flows out of an activity all get a token: a parallel split, no step needed.
        for flow in node.outgoing:
            self.arc(node.hrc_id, flow.place)

    def _exclusive(self, node: FlowNode) -> None:
        """A place where the choice or merge is made, and a silent transition per branch."""
        incoming, outgoing = node.incoming, node.outgoing
        extra = _without_id(node.extra)
        if len(incoming) == 1:  # a split (or a pass): the incoming flow's place chooses
            centre, merge, split = incoming[0].place, False, True
        elif len(outgoing) == 1:  # a merge: every branch steps into the outgoing flow's place
            centre, merge, split = outgoing[0].place, True, False
        else:
            centre, merge, split = node.hrc_id, True, True
            self.place(centre, **({"name": node.name} if node.name else {}))
        # The gateway's own data goes with the place that stands for it.
        self.place_by_id[centre].update(extra)
        if merge:
            for flow in incoming:
                step = self.transition(self.fresh(f"{node.hrc_id}_{flow.xml_id}"))
                self.arc(flow.place, step)
                self.arc(step, centre)
        if split:
            guards = self._guards(node)
            for flow in outgoing:
                step = self.transition(
                    self.fresh(f"{node.hrc_id}_{flow.xml_id}"),
                    guard=guards.get(flow.xml_id),
                )
                self.arc(centre, step)
                self.arc(step, flow.place)

    def _guards(self, node: FlowNode) -> dict[str, str]:
        """Each outgoing flow's condition; the default flow's is that none of the others holds."""
        conditions = {f.xml_id: f.condition for f in node.outgoing if f.condition is not None}
        default = node.default
        others = [c for f, c in conditions.items() if f != default]
        if default and others and len(others) == len(node.outgoing) - 1:
            conditions[default] = " and ".join(f"not ({c})" for c in others)
        return conditions

    def ends(self, events: list[FlowNode], *, start: bool) -> None:
        """The source (start=True) or sink place, and the silent transitions that reach it.

        One event is the place itself; several share a place `<process>_start` or
        `<process>_end`, and each is a silent transition (their own hrc:extra, which
        would describe a place, is then not read).
        """
        if not events:
            return
        if len(events) == 1:
            event = events[0]
            named = {"name": event.name} if event.name else {}
            end_place = self.place(event.hrc_id, **named, **_without_id(event.extra))
        else:
            kind = "start" if start else "end"
            end_place = self.place(self.fresh(f"{self.process_id}_{kind}"))
        shared = len(events) > 1
        for event in events:
            if start:
                # A start event puts a token in each of its outgoing flows (a parallel split).
                step = (
                    self.transition(event.hrc_id, label=event.name)
                    if shared
                    else self.transition(self.fresh(f"{event.hrc_id}_start"))
                )
                self.arc(end_place, step)
                for flow in event.outgoing:
                    self.arc(step, flow.place)
                continue
            # Each flow into an end event ends there on its own (the event merges them).
            for flow in event.incoming:
                if shared and len(event.incoming) == 1:
                    step = self.transition(event.hrc_id, label=event.name)
                elif len(event.incoming) == 1:
                    step = self.transition(self.fresh(f"{event.hrc_id}_end"))
                else:
                    step = self.transition(self.fresh(f"{event.hrc_id}_{flow.xml_id}"))
                self.arc(flow.place, step)
                self.arc(step, end_place)


def _without_id(extra: Json) -> Json:
    return {key: value for key, value in extra.items() if key != "id"}
