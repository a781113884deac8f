"""BPMN 2.0 export of collaboration patterns, with a diagram (BPMNDI) from the layout.

`pattern_to_bpmn` writes one pool per process and one lane per actor, so BPMN
tools (bpmn.io, Camunda Modeler, Signavio, ...) show the pattern as its
engineer drew it. The net becomes BPMN the reverse way of `bpmn.py`'s import:

| hrc-pattern/1 | BPMN |
| --- | --- |
| task (a transition with a performer) | a task in its performer's lane (a `userTask`, ... when the transition's `bpmn` key says so); a task with several input places gets a parallel gateway `<task>_join` before it |
| silent transition | a parallel gateway (it consumes all its inputs and produces all its outputs) |
| silent transition with a `timer` | an intermediate catch event with a timerEventDefinition (its timeDuration); several inputs get a parallel gateway `<id>_join` before it |
| silent transition with a `message` | an intermediate catch event with a messageEventDefinition, referring to the file's `<message>` of that name |
| silent transition with a `send` (and no `message`) | an intermediate throw event with a messageEventDefinition |
| a task or silent transition with a `send`, and a catch event of that message in another process | a message flow from the one to the other, between their pools |
| source place | a start event (followed by an exclusive gateway `<place>_split` when several transitions compete for its token; an event-based gateway when each of them is a catch event) |
| sink place | an end event, reached by a flow from each transition that marks it |
| any other place with one input and one output transition | a sequence flow |
| a place with several inputs or outputs | an exclusive gateway (a merge, a choice, or both) between sequence flows; a choice between catch events only is an event-based gateway (BPMN's deferred choice) |
| constraint | an association between the two tasks with `hrc:constraint="time"` (or space, func) |

What BPMN cannot say travels in `<hrc:extra>` (see `bpmn.py`): task
configuration, guards, initial tokens, workpieces, the declared pattern, and
any id XML cannot hold as written; `bpmn.bpmn_to_pattern` reads it back. The
keys an event shows (`timer`, `message`, `send`) stay in it too, with their
correlation and `cancels`, so the import gives them back exactly.
Positions come from the document's `layout` (`layout.lay_out` when it has
none): tasks, gateways and events at their nodes' centres, pools and lanes as
the layout's lane bands.

The import gives the same document back, not only the same behaviour: each
element written carries an `hrc:net` attribute saying what it stands for in
the net (`transition t1`, `place p2`, the `join`, `split` or `merge` of one, an
`arc`), and each process an `<hrc:net>` with its actors, its ids and arcs in
order, and its nodes' layout as given (none when the pattern had none); the
collaboration's `<hrc:extra>` orders the actors and constraints and gives in
full those BPMN cannot draw (an actor in no process, a constraint on a silent
step). `bpmn_marks` says how the import checks and reads them; a process
edited in another tool so that its marks no longer hold is read by the mapping.
Both are attributes and elements of the hrc namespace, which OMG's XSD allows
on every BPMN element.

A net BPMN cannot draw is refused with a FormatError naming the elements:
duplicate ids, and arcs to unknown nodes or between two places or two
transitions. Initial tokens travel in `<hrc:extra>` like the rest; other tools
start a case with one token at each start event, whatever the places say.
"""

import json
import re
import xml.etree.ElementTree as ET
from collections import defaultdict
from operator import itemgetter
from typing import Any

from hrc.engine.bpmn import (
    BPMN_NAMESPACE,
    BPMNDI_NAMESPACE,
    DC_NAMESPACE,
    DI_NAMESPACE,
    HRC_NAMESPACE,
)
from hrc.engine.bpmn_diagram import Drawing, Shape, Stack, point
from hrc.engine.bpmn_marks import ARC, JOIN, MARK, MERGE, PLACE, SPLIT, TRANSITION, mark
from hrc.engine.bpmn_net import TASK_KINDS
from hrc.engine.document import FormatError
from hrc.engine.issues import error
from hrc.engine.layout import TASK_HEIGHT, TASK_WIDTH, is_laid_out, lay_out_pattern
from hrc.engine.model import Actor, Pattern, Place, Process, Transition
from hrc.engine.rules import check_rules

Json = dict[str, Any]

XSI_NAMESPACE = "http://www.w3.org/2001/XMLSchema-instance"

for _prefix, _uri in (
    ("bpmn", BPMN_NAMESPACE),
    ("bpmndi", BPMNDI_NAMESPACE),
    ("dc", DC_NAMESPACE),
    ("di", DI_NAMESPACE),
    ("hrc", HRC_NAMESPACE),
    ("xsi", XSI_NAMESPACE),
):
    ET.register_namespace(_prefix, _uri)

TARGET_NAMESPACE = "urn:hrc:pattern"
EVENT_SIZE = 36.0
GATEWAY_SIZE = 50.0
JOIN_SIZE = 36.0
"""A join squeezed in before a task, in the gap between two columns."""
POOL_HEADER_WIDTH = 30.0
"""Less than layout.LANE_HEADER_WIDTH, so the nodes stay clear of the pool's header."""
UNREPRESENTABLE = ("duplicate-id", "unknown-node", "arc-kind")


def pattern_to_bpmn(pattern: Pattern) -> str:
    """The BPMN 2.0 XML of a pattern; raises FormatError when BPMN cannot represent it."""
    _check_representable(pattern)
    drawn = pattern if is_laid_out(pattern) else lay_out_pattern(pattern)
    return _Writer(drawn, pattern).text()


def _check_representable(pattern: Pattern) -> None:
    issues = [
        error("format", f"The model cannot be written as BPMN: {issue.message}", *issue.elements)
        for issue in check_rules(pattern)
        if issue.code in UNREPRESENTABLE
    ]
    if issues:
        raise FormatError(issues)


def _nodes(process: Process) -> list[Place | Transition]:
    return [*process.places, *process.transitions]


# Ids and text ------------------------------------------------------------------------------

_NCNAME = re.compile(r"[A-Za-z_][A-Za-z0-9_.\-]*")
_NOT_XML_TEXT = re.compile("[^\t\n\x20-\ud7ff\ue000-\ufffd\U00010000-\U0010ffff]")


def _is_text(value: str) -> bool:
    """Whether XML gives this string back exactly (it cannot hold some characters, nor a CR)."""
    return _NOT_XML_TEXT.search(value) is None


class _Ids:
    """XML ids: an element keeps its hrc id where that is an NCName not taken yet."""

    def __init__(self, pattern: Pattern) -> None:
        ids = [actor.id for actor in pattern.actors]
        for process in pattern.processes:
            ids += [process.id, *(node.id for node in _nodes(process))]
        self.reserved = {element_id for element_id in ids if _NCNAME.fullmatch(element_id)}
        self.taken: set[str] = set()

    def own(self, hrc_id: str, fallback: str) -> tuple[str, bool]:
        """(XML id, whether it is the hrc id) for an element that stands for `hrc_id`."""
        if _NCNAME.fullmatch(hrc_id) and hrc_id not in self.taken:
            self.taken.add(hrc_id)
            return hrc_id, True
        return self.fresh(fallback), False

    def fresh(self, base: str) -> str:
        base = re.sub(r"[^A-Za-z0-9_.\-]", "_", base)
        base = base if _NCNAME.fullmatch(base) else f"id_{base}"
        candidate, number = base, 1
        while candidate in self.taken or candidate in self.reserved:
            number += 1
            candidate = f"{base}_{number}"
        self.taken.add(candidate)
        return candidate


# Writing -----------------------------------------------------------------------------------


def _tag(local: str, namespace: str = BPMN_NAMESPACE) -> str:
    return f"{{{namespace}}}{local}"


class _Writer:
    def __init__(self, pattern: Pattern, original: Pattern) -> None:
        self.pattern = pattern
        """The pattern laid out, for the diagram."""
        self.original = original
        """The pattern as given, whose layout (or lack of it) the marks keep."""
        self.layouts: dict[str, Any] = {
            node.id: node.extra["layout"]
            for process in original.processes
            for node in _nodes(process)
            if "layout" in node.extra
        }
        self.ids = _Ids(pattern)
        self.drawing = Drawing()
        self.element_of: dict[str, str] = {}
        """hrc task id -> the XML id of its task (constraint ends)."""
        self.process_of_task: dict[str, ET.Element] = {}
        self.messages: dict[str, str] = {}
        """Message name -> the XML id of its `<message>`."""
        self.senders: list[tuple[str, str, str]] = []
        self.catchers: list[tuple[str, str, str]] = []
        """(process id, element, message name) of each sender and each message catch event."""
        layout = pattern.extra["layout"]
        self.width = float(layout["width"])
        self.bands: dict[str | None, tuple[float, float]] = {}
        for lane in layout["lanes"]:
            actor = lane.get("actor")
            self.bands.setdefault(
                actor if isinstance(actor, str) else None, (float(lane["y"]), float(lane["height"]))
            )
        self.stacks: dict[str, Stack] = {}
        bottom = 0.0
        for process in pattern.processes:
            stack = self._stack(process, bottom)
            self.stacks[process.id] = stack
            bottom = stack.bottom

    def band_key(self, actor_id: str) -> str | None:
        """The layout's lane of an actor; a performer that is no actor is in the lane of None."""
        return actor_id if self.pattern.actor(actor_id) is not None else None

    def _stack(self, process: Process, top: float) -> Stack:
        """The process' pool from `top` down: the layout's bands of its actors, one under another.

        The layout shares an actor's band among the processes it works in; BPMN draws
        each pool apart, so a process' lanes are moved together under the pool above.
        """
        keys = dict.fromkeys(self.band_key(actor) for actor in _lane_actors(process))
        bands = sorted(
            ((self.bands[key], key) for key in keys if key in self.bands), key=itemgetter(0)
        )
        if not bands:
            ys = [
                centre[1] for node in _nodes(process) if (centre := point(node.extra)) is not None
            ] or [0.0]
            span = (min(ys) - TASK_HEIGHT, max(ys) - min(ys) + 2 * TASK_HEIGHT)
            return Stack([(span[0], top, span[1])], {}, top, top + span[1])
        stack = Stack([], {}, top, top)
        for (layout_top, height), key in bands:
            stack.moves.append((layout_top, stack.bottom, height))
            stack.lanes[key] = (stack.bottom, height)
            stack.bottom += height
        return stack

    def text(self) -> str:
        pattern = self.pattern
        root = ET.Element(
            _tag("definitions"),
            {
                "id": self.ids.fresh("definitions"),
                "targetNamespace": TARGET_NAMESPACE,
                "exporter": "hrc",
                "exporterVersion": "1",
            },
        )
        document_extra: Json = dict(self.original.extra)
        if pattern.name and _is_text(pattern.name):
            root.set("name", pattern.name)
        if not (pattern.name and _is_text(pattern.name) and pattern.name == pattern.name.strip()):
            document_extra["name"] = pattern.name  # the importer strips names and needs one
        if pattern.declared_pattern is not None:
            root.set(_tag("declaredPattern", HRC_NAMESPACE), pattern.declared_pattern)
        collaboration = ET.SubElement(
            root, _tag("collaboration"), id=self.ids.fresh("collaboration")
        )
        # The actors' and constraints' order, which import restores; an actor without a lane
        # and a constraint without an association are given in full.
        laned = {actor for process in pattern.processes for actor in _lane_actors(process)}
        document_extra["actors"] = [
            actor.id if actor.id in laned else {"id": actor.id, "type": actor.type, **actor.extra}
            for actor in pattern.actors
        ]
        processes = []
        pools: list[tuple[str, Process]] = []
        for process in pattern.processes:
            element, pool = self._process(process, collaboration)
            processes.append(element)
            pools.append((pool, process))
        self._message_flows(collaboration)
        document_extra["constraints"] = self._constraints(collaboration)
        _add_extra(collaboration, document_extra)
        for name, message_id in self.messages.items():
            message = ET.SubElement(root, _tag("message"), id=message_id)
            if _is_text(name):
                message.set("name", name)
        for element in processes:
            root.append(element)
        pool_bounds = [
            (pool, (0.0, stack.top, self.width, stack.bottom - stack.top))
            for pool, process in pools
            for stack in [self.stacks[process.id]]
        ]
        self.drawing.write(root, collaboration.get("id", ""), pool_bounds, self.ids.fresh)
        ET.indent(root)
        return (
            '<?xml version="1.0" encoding="UTF-8"?>\n'
            + ET.tostring(root, encoding="unicode")
            + "\n"
        )

    # Processes.

    def _process(self, process: Process, collaboration: ET.Element) -> tuple[ET.Element, str]:
        xml_id, faithful = self.ids.own(process.id, "process")
        element = ET.Element(_tag("process"), id=xml_id, isExecutable="false")
        extra: Json = dict(process.extra)
        if not faithful:
            extra["id"] = process.id
        name = extra.get("name")
        if isinstance(name, str) and name and _is_text(name):
            element.set("name", name)
            del extra["name"]
        if process.workpiece is not None:
            if _is_text(process.workpiece):
                element.set(_tag("workpiece", HRC_NAMESPACE), process.workpiece)
            else:
                extra["workpiece"] = process.workpiece
        net = {
            "actors": list(process.actors),
            "places": [place.id for place in process.places],
            "transitions": [transition.id for transition in process.transitions],
            "arcs": [list(arc) for arc in process.arcs],
            "layout": {n.id: self.layouts[n.id] for n in _nodes(process) if n.id in self.layouts},
        }
        _add_extra(element, extra, net)
        pool = self.ids.fresh(f"{xml_id}_pool")
        participant = ET.SubElement(collaboration, _tag("participant"), id=pool, processRef=xml_id)
        participant.set("name", element.get("name") or xml_id)
        _ProcessWriter(self, process, element).write()
        return element, pool

    def message(self, name: str) -> str:
        """The XML id of the `<message>` of this name, declared on first use."""
        if name not in self.messages:
            self.messages[name] = self.ids.fresh(f"message_{name}")
        return self.messages[name]

    def _message_flows(self, collaboration: ET.Element) -> None:
        """A message flow from each sender to each catch event of its message in another pool."""
        for sender_process, source, name in self.senders:
            for catcher_process, target, wanted in self.catchers:
                if wanted != name or catcher_process == sender_process:
                    continue
                flow_id = self.ids.fresh(f"message_flow_{source}_{target}")
                ET.SubElement(
                    collaboration,
                    _tag("messageFlow"),
                    id=flow_id,
                    sourceRef=source,
                    targetRef=target,
                    messageRef=self.messages[name],
                )
                self.drawing.message_edges.append((flow_id, source, target))

    def _constraints(self, collaboration: ET.Element) -> list[str | Json]:
        """Draws each constraint between two tasks; returns the constraints' order for import."""
        order: list[str | Json] = []
        for constraint in self.pattern.constraints:
            source = self.element_of.get(constraint.source)
            target = self.element_of.get(constraint.target)
            if source is None or target is None:
                # A constraint on a silent step: the rules report it, BPMN has no place for it.
                order.append(
                    {
                        "from": constraint.source,
                        "to": constraint.target,
                        "type": constraint.type,
                        **constraint.extra,
                    }
                )
                continue
            home = self.process_of_task.get(constraint.source, collaboration)
            association_id = self.ids.fresh(f"{constraint.type}_{source}_{target}")
            association = ET.Element(
                _tag("association"),
                id=association_id,
                sourceRef=source,
                targetRef=target,
                associationDirection="One",
            )
            extra: Json = dict(constraint.extra)
            if _is_text(constraint.type):
                association.set(_tag("constraint", HRC_NAMESPACE), constraint.type)
            else:
                association.set(_tag("constraint", HRC_NAMESPACE), "")
                extra["type"] = constraint.type
            _add_extra(association, extra)
            home.append(association)
            self.drawing.edges.append((association_id, source, target))
            order.append(association_id)
        return order


def _lane_actors(process: Process) -> list[str]:
    """The process' actors, then any performer that is not one of them."""
    performers = [t.performer for t in process.transitions if t.performer is not None]
    return list(dict.fromkeys([*process.actors, *performers]))


class _ProcessWriter:
    """One process' lanes, flow nodes and sequence flows."""

    def __init__(self, writer: _Writer, process: Process, element: ET.Element) -> None:
        self.writer = writer
        self.ids = writer.ids
        self.process = process
        self.stack = writer.stacks[process.id]
        self.element = element
        self.inputs: dict[str, list[str]] = defaultdict(list)
        self.outputs: dict[str, list[str]] = defaultdict(list)
        self.producers: dict[str, list[str]] = defaultdict(list)
        self.consumers: dict[str, list[str]] = defaultdict(list)
        transitions = {t.id for t in process.transitions}
        for source, target in process.arcs:
            if target in transitions:
                self.inputs[target].append(source)
                self.consumers[source].append(target)
            else:
                self.outputs[source].append(target)
                self.producers[target].append(source)
        self.node_of: dict[str, str] = {}
        """hrc transition id -> the XML id of its element."""
        self.entry_of: dict[str, str] = {}
        """hrc transition id -> the element its incoming flows go to (the task, or its join)."""
        self.nodes: list[ET.Element] = []
        self.flows: list[ET.Element] = []
        self.definitions: dict[str, ET.Element] = {}
        """XML id of an event -> its event definition (a timer or a message)."""
        self.catching: set[str] = set()
        """The XML ids of the catch events, which an event-based gateway may lead to."""

    def write(self) -> None:
        lane_set = ET.SubElement(
            self.element, _tag("laneSet"), id=self.ids.fresh(f"{self.element.get('id')}_lanes")
        )
        lanes = {actor: self._lane(lane_set, actor) for actor in _lane_actors(self.process)}
        if not lanes:
            self.element.remove(lane_set)
        for transition in self.process.transitions:
            self._transition(transition, lanes)
        for place in self.process.places:
            self._place(place)
        incoming: dict[str, list[str]] = defaultdict(list)
        outgoing: dict[str, list[str]] = defaultdict(list)
        for flow in self.flows:
            outgoing[flow.get("sourceRef", "")].append(flow.get("id", ""))
            incoming[flow.get("targetRef", "")].append(flow.get("id", ""))
        for node in self.nodes:
            # Optional in BPMN, but some tools read a node's flows only from these.
            node_id = node.get("id", "")
            for local, flows in (("incoming", incoming[node_id]), ("outgoing", outgoing[node_id])):
                for flow_id in flows:
                    ET.SubElement(node, _tag(local)).text = flow_id
            if node_id in self.definitions:  # after the flows, as BPMN's schema orders them
                node.append(self.definitions[node_id])
            self.element.append(node)
        for flow in self.flows:
            self.element.append(flow)

    def _lane(self, lane_set: ET.Element, actor_id: str) -> ET.Element:
        xml_id, faithful = self.ids.own(actor_id, f"lane_{actor_id}")
        lane = ET.SubElement(lane_set, _tag("lane"), id=xml_id)
        actor: Actor | None = self.writer.pattern.actor(actor_id)
        extra: Json = dict(actor.extra) if actor else {}
        if not faithful:
            extra["id"] = actor_id
        name = extra.pop("name", None)
        if not (isinstance(name, str) and name and _is_text(name)) or name == actor_id:
            if name is not None:
                extra["name"] = name  # import takes a lane named as its actor for unnamed
            name = actor_id if _is_text(actor_id) else None
        if name is not None:
            lane.set("name", name)
        if actor is not None:
            lane.set(_tag("actorType", HRC_NAMESPACE), actor.type)
        _add_extra(lane, extra)
        band = self.stack.lanes.get(self.writer.band_key(actor_id))
        if band is not None:
            left = POOL_HEADER_WIDTH
            self.writer.drawing.pool_lanes.append(
                (xml_id, (left, band[0], self.writer.width - left, band[1]))
            )
        return lane

    # Transitions.

    def _transition(self, transition: Transition, lanes: dict[str, ET.Element]) -> None:
        extra: Json = {k: v for k, v in transition.extra.items() if k != "layout"}
        kind = "parallelGateway"
        if transition.is_task:
            wanted = extra.get("bpmn", "task")
            kind = wanted if wanted in TASK_KINDS else "task"
            if kind != "task":
                del extra["bpmn"]  # the element's kind says it
        xml_id, faithful = self.ids.own(transition.id, "transition")
        if not faithful:
            extra["id"] = transition.id
        event = None if transition.is_task else self._event(transition, xml_id)
        if event is not None:
            kind, definition = event
            self.definitions[xml_id] = definition
            if kind == "intermediateCatchEvent":
                self.catching.add(xml_id)
        element = ET.Element(
            _tag(kind), {"id": xml_id, _tag(MARK, HRC_NAMESPACE): mark(TRANSITION, xml_id)}
        )
        label = transition.label
        if label is not None:
            if label and _is_text(label):
                element.set("name", label)
            else:
                extra["label"] = label
        _add_extra(element, extra)
        self.nodes.append(element)
        self.node_of[transition.id] = xml_id
        self.entry_of[transition.id] = xml_id
        centre = point(transition.extra) or (0.0, 0.0)
        if transition.is_task:
            self.writer.element_of[transition.id] = xml_id
            self.writer.process_of_task[transition.id] = self.element
            self._shape(xml_id, centre, (TASK_WIDTH, TASK_HEIGHT))
            lane = lanes.get(transition.performer or "")
            if lane is not None:
                ET.SubElement(lane, _tag("flowNodeRef")).text = xml_id
            self._sender(transition, xml_id)
        elif event is not None:
            self._shape(xml_id, centre, (EVENT_SIZE, EVENT_SIZE))
        else:
            self._shape(xml_id, centre, (GATEWAY_SIZE, GATEWAY_SIZE))
        if len(self.inputs[transition.id]) > 1 and kind != "parallelGateway":
            # BPMN merges flows into a task or an event; the net's transition waits for all its inputs.
            join = self.ids.fresh(f"{xml_id}_join")
            self._node("parallelGateway", join, mark(JOIN, xml_id))
            width = TASK_WIDTH if transition.is_task else EVENT_SIZE
            left = centre[0] - width / 2 - JOIN_SIZE / 2 - 2
            self._shape(join, (left, centre[1]), (JOIN_SIZE, JOIN_SIZE))
            self._flow(join, xml_id)
            self.entry_of[transition.id] = join

    def _event(self, transition: Transition, xml_id: str) -> tuple[str, ET.Element] | None:
        """(kind, event definition) of a silent transition that waits for a timer or a message,
        or sends one; None for a plain silent step (a parallel gateway)."""
        timer, message = transition.extra.get("timer"), transition.extra.get("message")
        if isinstance(timer, str) and _is_text(timer):
            definition = ET.Element(
                _tag("timerEventDefinition"), id=self.ids.fresh(f"{xml_id}_timer")
            )
            duration = ET.SubElement(definition, _tag("timeDuration"))
            duration.set(_tag("type", XSI_NAMESPACE), "bpmn:tFormalExpression")
            duration.text = timer
            return "intermediateCatchEvent", definition
        name = _message_name(message)
        if name is not None:
            self.writer.catchers.append((self.process.id, xml_id, name))
            return "intermediateCatchEvent", self._message_definition(xml_id, name)
        name = _message_name(transition.extra.get("send"))
        if name is not None:
            self._sender(transition, xml_id)
            return "intermediateThrowEvent", self._message_definition(xml_id, name)
        return None

    def _message_definition(self, xml_id: str, name: str) -> ET.Element:
        return ET.Element(
            _tag("messageEventDefinition"),
            id=self.ids.fresh(f"{xml_id}_message"),
            messageRef=self.writer.message(name),
        )

    def _sender(self, transition: Transition, xml_id: str) -> None:
        name = _message_name(transition.extra.get("send"))
        if name is not None:
            self.writer.message(name)
            self.writer.senders.append((self.process.id, xml_id, name))

    # Places.

    def _place(self, place: Place) -> None:
        extra: Json = {k: v for k, v in place.extra.items() if k != "layout"}
        if place.tokens is not None:
            extra["tokens"] = place.tokens
        name = extra.pop("name", None)
        if name is not None and not (isinstance(name, str) and name and _is_text(name)):
            extra["name"] = name
            name = None
        producers = [self.node_of[t] for t in self.producers[place.id]]
        consumers = [self.entry_of[t] for t in self.consumers[place.id]]
        centre = point(place.extra) or (0.0, 0.0)

        def carry(element: ET.Element, faithful: bool) -> None:
            """The element that stands for the place takes its name and data."""
            data = dict(extra) if faithful else {**extra, "id": place.id}
            if name is not None:
                element.set("name", name)
            _add_extra(element, data)

        if not producers:
            event, faithful = self.ids.own(place.id, f"{place.id}_start")
            start = self._node("startEvent", event, mark(PLACE, event))
            carry(start, faithful)
            if len(consumers) > 1:
                split = self.ids.fresh(f"{event}_split")
                self._node(self._choice(consumers), split, mark(SPLIT, event))
                self._shape(event, (centre[0] - 25, centre[1]), (EVENT_SIZE, EVENT_SIZE))
                self._shape(split, (centre[0] + 25, centre[1]), (GATEWAY_SIZE, GATEWAY_SIZE))
                self._flow(event, split)
                for consumer in consumers:
                    self._flow(split, consumer)
            else:
                self._shape(event, centre, (EVENT_SIZE, EVENT_SIZE))
                for consumer in consumers:
                    self._flow(event, consumer)
        elif not consumers:
            event, faithful = self.ids.own(place.id, f"{place.id}_end")
            carry(self._node("endEvent", event, mark(PLACE, event)), faithful)
            self._shape(event, centre, (EVENT_SIZE, EVENT_SIZE))
            for producer in producers:
                self._flow(producer, event)
        elif len(producers) == 1 and len(consumers) == 1:
            flow_id, faithful = self.ids.own(place.id, f"{place.id}_flow")
            carry(self._flow(producers[0], consumers[0], flow_id), faithful)
        elif len(producers) == 1:  # a choice: the flow into the gateway is the place
            split = self.ids.fresh(f"{place.id}_split")
            flow_id, faithful = self.ids.own(place.id, f"{place.id}_flow")
            self._node(self._choice(consumers), split, mark(SPLIT, flow_id))
            self._shape(split, centre, (GATEWAY_SIZE, GATEWAY_SIZE))
            carry(self._flow(producers[0], split, flow_id), faithful)
            for consumer in consumers:
                self._flow(split, consumer)
        elif len(consumers) == 1:  # a merge: the flow out of the gateway is the place
            merge = self.ids.fresh(f"{place.id}_merge")
            flow_id, faithful = self.ids.own(place.id, f"{place.id}_flow")
            self._node("exclusiveGateway", merge, mark(MERGE, flow_id))
            self._shape(merge, centre, (GATEWAY_SIZE, GATEWAY_SIZE))
            for producer in producers:
                self._flow(producer, merge)
            carry(self._flow(merge, consumers[0], flow_id), faithful)
        else:
            gateway, faithful = self.ids.own(place.id, f"{place.id}_gateway")
            carry(self._node(self._choice(consumers), gateway, mark(PLACE, gateway)), faithful)
            self._shape(gateway, centre, (GATEWAY_SIZE, GATEWAY_SIZE))
            for producer in producers:
                self._flow(producer, gateway)
            for consumer in consumers:
                self._flow(gateway, consumer)

    def _choice(self, consumers: list[str]) -> str:
        """The gateway of a place's choice: event-based when every branch waits for an event."""
        return "eventBasedGateway" if set(consumers) <= self.catching else "exclusiveGateway"

    def _node(self, kind: str, xml_id: str, stands_for: str) -> ET.Element:
        element = ET.Element(_tag(kind), {"id": xml_id, _tag(MARK, HRC_NAMESPACE): stands_for})
        self.nodes.append(element)
        return element

    def _flow(self, source: str, target: str, place: str | None = None) -> ET.Element:
        """A sequence flow: the place of that XML id, or an arc between what its ends stand for."""
        flow_id = place or self.ids.fresh(f"flow_{source}_{target}")
        flow = ET.Element(
            _tag("sequenceFlow"),
            {
                "id": flow_id,
                _tag(MARK, HRC_NAMESPACE): mark(PLACE, place) if place else mark(ARC),
                "sourceRef": source,
                "targetRef": target,
            },
        )
        self.flows.append(flow)
        self.writer.drawing.edges.append((flow_id, source, target))
        return flow

    def _shape(self, element: str, centre: tuple[float, float], size: tuple[float, float]) -> None:
        """A shape at its layout position, moved into the process' pool."""
        x, y = centre
        self.writer.drawing.shapes.append(Shape(element, (x, self.stack.y(y)), size))


def _message_name(value: object) -> str | None:
    """The name of a `send` or `message` object; None when there is none to show."""
    if not isinstance(value, dict):
        return None
    name = value.get("name")
    return name if isinstance(name, str) and name else None


def _add_extra(element: ET.Element, data: Json, net: Json | None = None) -> None:
    """The keys BPMN cannot carry, as JSON in `<extensionElements><hrc:extra>`, and a
    process' `<hrc:net>` (`bpmn_marks`).

    ASCII-escaped JSON, so any string (even one XML cannot hold) survives.
    """
    if not data and net is None:
        return
    holder = ET.Element(_tag("extensionElements"))
    for local, value in (("extra", data or None), (MARK, net)):
        if value is not None:
            ET.SubElement(holder, _tag(local, HRC_NAMESPACE)).text = json.dumps(
                value, ensure_ascii=True, sort_keys=True
            )
    element.insert(0, holder)  # extensionElements comes first in every BPMN element
