"""Reads one BPMN process, its sub-processes and called processes, into flow nodes and scopes.

Sub-processes and call activities are flattened: each becomes a scope
between two silent steps, `<name>: begins` and `<name>: ends`, with its
contents in between; a task with boundary events gets a scope of its own.
Events become the keys of their transitions (`message`, `send`, `timer`,
`guard`, `cancels`, `rewrite`). `bpmn.py`'s docstring gives the mapping;
`bpmn_net.FlowNet` builds the net.
"""

import re
import xml.etree.ElementTree as ET
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, Protocol

from hrc.engine.bpmn_conditions import translate
from hrc.engine.bpmn_net import (
    EVENT_KINDS,
    GATEWAY_KINDS,
    MAX_INCLUSIVE_BRANCHES,
    TASK_KINDS,
    Flow,
    FlowNode,
    Scope,
    describe,
)
from hrc.engine.bpmn_xml import bpmn_name, children, text_of
from hrc.engine.model import Pattern

Json = dict[str, Any]

FLOW_NODE_KINDS = TASK_KINDS | GATEWAY_KINDS | EVENT_KINDS
GLOBAL_TASKS = frozenset(
    {
        "globalTask",
        "globalUserTask",
        "globalManualTask",
        "globalScriptTask",
        "globalBusinessRuleTask",
    }
)
# Elements of a process that carry no control flow: read elsewhere or ignored.
PROCESS_IGNORED = frozenset(
    {
        "documentation",
        "extensionElements",
        "auditing",
        "monitoring",
        "property",
        "laneSet",
        "sequenceFlow",
        "association",
        "textAnnotation",
        "group",
        "dataObject",
        "dataObjectReference",
        "dataStoreReference",
        "ioSpecification",
        "ioBinding",
        "resourceRole",
        "performer",
        "humanPerformer",
        "potentialOwner",
        "correlationSubscription",
        "supports",
        "dataInputAssociation",
        "dataOutputAssociation",
        "standardLoopCharacteristics",
        "multiInstanceLoopCharacteristics",
        "incoming",
        "outgoing",
    }
)
REFUSED_WHY = {
    "complexGateway": "a complex gateway's activation rule has no Petri net mapping in hrc",
    "adHocSubProcess": "its tasks run in any order and number, which hrc's nets do not model",
    "transaction": "transactions (cancel and compensation) are not imported",
}
CORRELATION_SEND = {"case": "=case.id"}
CORRELATION_AWAIT = {"case": "case.id"}
MAX_COPIES = 20
"""Multi-instance copies made at import; a larger cardinality is imported once, to rewrite."""
DURATION = re.compile(
    r"^P(?!$)(\d+(\.\d+)?D)?(T(?=\d)(\d+(\.\d+)?H)?(\d+(\.\d+)?M)?(\d+(\.\d+)?S)?)?$"
)


class Reading(Protocol):
    """What the file's reader gives the process reader."""

    def fail(self, message: str, *elements: str) -> None: ...

    def fresh(self, base: str) -> str: ...

    def hrc_id(self, xml_id: str) -> str: ...

    def extra(self, element: ET.Element, where: str) -> Json: ...

    def process_element(self, xml_id: str) -> ET.Element | None: ...

    def global_task(self, xml_id: str) -> ET.Element | None: ...

    def definition_name(self, reference: str | None) -> str | None: ...

    def message_in(self, xml_id: str) -> str | None: ...

    def messages_out(self, xml_id: str) -> list[str]: ...

    def signal_thrown(self, name: str) -> bool: ...

    def event_definition(self, xml_id: str) -> ET.Element | None: ...


@dataclass
class Trigger:
    """An event's definition: its kind (`message`, `timer`, ...) and what it names."""

    kind: str
    element: ET.Element
    name: str | None = None


@dataclass
class ProcessGraph:
    """One process' flow nodes, flows and scopes, flattened, and each task's lane element."""

    root: Scope
    nodes: list[FlowNode] = field(default_factory=list)
    flows: list[Flow] = field(default_factory=list)
    starts: dict[str, list[FlowNode]] = field(default_factory=dict)
    """Scope id -> its start events."""
    ends: dict[str, list[FlowNode]] = field(default_factory=dict)
    scopes: dict[str, Scope] = field(default_factory=dict)
    tasks: dict[str, list[str]] = field(default_factory=dict)
    """hrc id of each task -> the XML ids its lane is looked up by: its own, its outermost activity's."""
    inlined: list[tuple[Scope, str, Pattern]] = field(default_factory=list)
    """Published patterns called: the call activity's scope, its id, the pattern."""


@dataclass
class _Boundary:
    node: FlowNode
    trigger: Trigger | None
    interrupting: bool
    scope: Scope
    caught: bool = False
    """Whether an end or throw event inside its activity throws what it catches."""


class ProcessReader:
    """Reads one `<process>` element into a `ProcessGraph`, reporting refusals to the reading."""

    def __init__(
        self,
        reading: Reading,
        process: ET.Element,
        process_id: str,
        called: Callable[[list[str]], Pattern | None],
    ) -> None:
        self.reading = reading
        self.element = process
        self.called = called
        root = Scope(process_id, None, "", "")
        self.graph = ProcessGraph(root)
        self.graph.scopes[process_id] = root
        self.refused: set[str] = set()
        """XML ids of elements refused: flows touching them are not reported again."""
        self.boundaries: list[_Boundary] = []
        self.boundary_of_scope: dict[str, list[_Boundary]] = {}
        self.throwers: list[tuple[FlowNode, Trigger]] = []
        self.links: list[tuple[FlowNode, str, bool]] = []
        self.calling: list[str] = [process.get("id", "")]
        self.begins: dict[str, FlowNode] = {}
        """Scope id -> the step that begins it."""
        self._finishes: dict[str, FlowNode] = {}
        self._entered_by: dict[int, Scope] = {}
        """id() of a scope's begin step -> the scope, for boundary events attached to it."""

    def read(self) -> ProcessGraph:
        root = self.graph.root
        self._container(self.element, root, "", None)
        if root.place is not None:
            # The process' own scope, for its event sub-processes: from its start to its end.
            for start in self.graph.starts.get(root.hrc_id, []):
                start.post.append(root.place)
            for end in self.graph.ends.get(root.hrc_id, []):
                end.cancels_places.append(root.place)
        self._route_throws()
        self._links()
        self._inclusive_blocks()
        self._deferred_choices()
        return self.graph

    def _deferred_choices(self) -> None:
        """An event-based gateway's outgoing flows share one place: its events race for it."""
        for gateway in self.graph.nodes:
            if gateway.kind != "eventBasedGateway":
                continue
            single = len(gateway.incoming) == 1
            centre = gateway.incoming[0].place if single else gateway.hrc_id
            for flow in gateway.outgoing:
                flow.place = centre

    # Containers: the process, sub-processes, called processes.

    def _container(self, element: ET.Element, scope: Scope, prefix: str, outer: str | None) -> None:
        """Reads the flow nodes and flows of a process or sub-process into the scope."""
        entry: dict[str, FlowNode] = {}
        exit_: dict[str, FlowNode] = {}
        pending: list[ET.Element] = []
        starts: list[FlowNode] = []
        ends: list[FlowNode] = []
        for child in element:
            local = bpmn_name(child)
            if local is None or local in PROCESS_IGNORED:
                continue
            xml_id = child.get("id", "")
            if not xml_id:
                self.reading.fail(f"A <{local}> in {element.get('id', 'a process')} has no id.")
                continue
            if local == "boundaryEvent":
                pending.append(child)
                continue
            read = self._flow_node(child, local, scope, prefix, outer)
            if read is None:
                self.refused.add(xml_id)
                continue
            entry[xml_id], exit_[xml_id] = read
            if read[0].kind == "startEvent":
                starts.append(read[0])
            elif read[0].kind == "endEvent":
                ends.append(read[0])
        for child in pending:
            node = self._boundary(child, scope, prefix, entry, exit_)
            if node is not None:
                entry[child.get("id", "")] = exit_[child.get("id", "")] = node
        self._flows(element, scope, prefix, entry, exit_)
        self._implicit_ends(scope, entry, exit_, starts, ends)
        self.graph.starts[scope.hrc_id] = starts
        self.graph.ends[scope.hrc_id] = ends

    def _node(
        self,
        kind: str,
        xml_id: str,
        hrc_id: str,
        name: str | None,
        scope: Scope,
        extra: Json | None = None,
    ) -> FlowNode:
        node = FlowNode(kind, xml_id, hrc_id, name, extra or {}, scope)
        self.graph.nodes.append(node)
        return node

    def _flow_node(
        self, element: ET.Element, local: str, scope: Scope, prefix: str, outer: str | None
    ) -> tuple[FlowNode, FlowNode] | None:
        """The node flows enter and the node they leave (one node, or a scope's two steps)."""
        xml_id = element.get("id", "")
        name = (element.get("name") or "").strip() or None
        what = describe(local, xml_id, name)
        if element.get("isForCompensation") == "true":
            undone = self._compensated(xml_id)
            self.reading.fail(
                f"The {what} compensates {undone or 'another activity'}: compensation is not "
                "imported; draw the undoing steps as ordinary tasks on an error path.",
                xml_id,
            )
            return None
        if local in REFUSED_WHY:
            self.reading.fail(f"The {what} cannot be imported: {REFUSED_WHY[local]}.", xml_id)
            return None
        if local == "subProcess" and element.get("triggeredByEvent") == "true":
            self._event_sub_process(element, scope, prefix, outer)
            return None
        if local in ("subProcess", "callActivity"):
            return self._activity_scope(element, local, scope, prefix, outer)
        if local not in FLOW_NODE_KINDS:
            self.reading.fail(f"The {what} cannot be imported: hrc does not map <{local}>.", xml_id)
            return None
        node = self._node(
            local,
            xml_id,
            prefix + self.reading.hrc_id(xml_id),
            name,
            scope,
            self.reading.extra(element, what),
        )
        node.default = element.get("default")
        if local in TASK_KINDS:
            self.graph.tasks[node.hrc_id] = [xml_id] + ([outer] if outer else [])
            self._task_messages(node)
            self._loops(element, node)
        elif local in EVENT_KINDS and not self._event(element, node):
            self.refused.add(xml_id)
            return None
        if local == "inclusiveGateway":
            node.keys.setdefault("bpmn", "inclusiveGateway")
        return node, node

    # Activities with contents: sub-processes and call activities.

    def _activity_scope(
        self, element: ET.Element, local: str, scope: Scope, prefix: str, outer: str | None
    ) -> tuple[FlowNode, FlowNode] | None:
        xml_id = element.get("id", "")
        name = (element.get("name") or "").strip() or None
        what = describe(local, xml_id, name)
        contents: ET.Element | None = element
        inner_prefix = prefix
        pattern: Pattern | None = None
        if local == "callActivity":
            callee = self._called(element, what)
            if callee is None:
                return None
            contents, pattern = callee.process, callee.pattern
            inner_prefix = f"{prefix}{self.reading.hrc_id(xml_id)}."
        elif not any(
            bpmn_name(c) in FLOW_NODE_KINDS | {"subProcess", "callActivity"} for c in element
        ):
            contents = None
        hrc_id = prefix + self.reading.hrc_id(xml_id)
        if contents is None and pattern is None:
            # A collapsed activity with nothing in it is one task.
            node = self._node(local, xml_id, hrc_id, name, scope, self.reading.extra(element, what))
            node.keys.setdefault("bpmn", local)
            self.graph.tasks[hrc_id] = [xml_id] + ([outer] if outer else [])
            if local == "callActivity" and not element.get("calledElement"):
                node.keys["rewrite"] = (
                    f"The {what} names no called element: imported as one task; draw "
                    "the tasks it calls in its place."
                )
            self._task_messages(node)
            self._loops(element, node)
            return node, node
        begin = self._node("begin", xml_id, hrc_id, name, scope, self.reading.extra(element, what))
        finish = self._node("finish", xml_id, self.reading.fresh(f"{hrc_id}_ends"), name, scope)
        inner = self._scope(hrc_id, scope, begin, finish)
        self._loops(element, begin)
        if begin.loop is not None:
            finish.loop_head = begin  # the step back goes from its end to its beginning
        if pattern is not None:
            self.graph.inlined.append((inner, hrc_id, pattern))
            return begin, finish
        assert contents is not None
        self.calling.append(contents.get("id", ""))
        self._container(contents, inner, inner_prefix, outer or xml_id)
        self.calling.pop()
        return begin, finish

    def _event_sub_process(
        self, element: ET.Element, host: Scope, prefix: str, outer: str | None
    ) -> None:
        """An interrupting event sub-process: a boundary event on the scope that holds it.

        Its start event's trigger takes the host's scope place and cancels its
        contents; the sub-process' contents then run, and its end continues where
        the host's would (the process' end, at top level).
        """
        xml_id = element.get("id", "")
        name = (element.get("name") or "").strip() or None
        what = describe("eventSubProcess", xml_id, name)
        starts = children(element, "startEvent")
        why = None
        if len(starts) != 1:
            why = f"it has {len(starts)} start events; hrc imports one, as its trigger"
        elif starts[0].get("isInterrupting", "true") == "false":
            why = (
                "it does not interrupt; hrc imports interrupting event sub-processes: draw "
                "this one as a non-interrupting boundary event on the activity it runs beside"
            )
        if why is not None:
            self.reading.fail(f"The {what} cannot be imported: {why}.", xml_id)
            self.refused.add(xml_id)
            return
        start = starts[0]
        kind = self._trigger(start, self._node("startEvent", "", "", None, host))
        self.graph.nodes.pop()  # the probe above only read the trigger
        if kind is None:
            self.reading.fail(
                f"The {what} cannot be imported: its start event has no trigger (message, "
                "timer, error, signal, ...), so nothing would ever start it.",
                xml_id,
            )
            self.refused.add(xml_id)
            return
        if kind.kind in ("compensate", "cancel", "reference"):
            self.reading.fail(
                f"The {what} starts on a {kind.kind} event: compensation and cancellation are "
                "not imported.",
                xml_id,
            )
            self.refused.add(xml_id)
            return
        if host.place is None:
            host.place = self.reading.fresh(f"{host.hrc_id}_running")
        trigger_id = prefix + self.reading.hrc_id(start.get("id", ""))
        catch = self._node(
            "boundaryEvent",
            start.get("id", ""),
            self.reading.fresh(f"{trigger_id}_trigger"),
            (start.get("name") or "").strip() or name,
            host.parent or host,
            self.reading.extra(element, what),
        )
        trigger = self._trigger(start, catch)
        catch.pre.append(host.place)
        catch.cancels.append(host)
        boundary = _Boundary(catch, trigger, True, host)
        self.boundaries.append(boundary)
        self.boundary_of_scope.setdefault(host.hrc_id, []).append(boundary)
        self._event_keys(catch, trigger, catching=True, what=what)
        hrc_id = prefix + self.reading.hrc_id(xml_id)
        begin = self._node("begin", xml_id, hrc_id, name, host)
        finish = self._node("finish", xml_id, self.reading.fresh(f"{hrc_id}_ends"), name, host)
        inner = self._scope(hrc_id, host, begin, finish)
        self.synthetic_flow(catch, begin, host)
        self._container(element, inner, prefix, outer or xml_id)
        for inner_start in self.graph.starts.get(inner.hrc_id, []):
            # The trigger is the boundary event's: inside, the start is a plain one.
            for key in ("message", "timer", "guard", "rewrite"):
                inner_start.keys.pop(key, None)
        if host.parent is None:
            finish.to_sink = host
        else:
            finish.post_flows = self._finishes[host.hrc_id].outgoing

    def _scope(self, hrc_id: str, parent: Scope, begin: FlowNode, finish: FlowNode) -> Scope:
        """A scope between two steps: begin marks its source and scope places, finish takes them."""
        fresh = self.reading.fresh
        inner = Scope(
            hrc_id,
            parent,
            fresh(f"{hrc_id}_start"),
            fresh(f"{hrc_id}_done"),
            fresh(f"{hrc_id}_scope"),
        )
        self.graph.scopes[hrc_id] = inner
        self.begins[hrc_id], self._finishes[hrc_id] = begin, finish
        self._entered_by[id(begin)] = inner
        begin.post += [inner.source, inner.place or ""]
        finish.pre += [inner.sink, inner.place or ""]
        finish.cancels_places = inner.armed
        return inner

    def _called(self, element: ET.Element, what: str) -> "_Callee | None":
        """What a call activity calls; None once refused.

        A process of the file, else a global task or nothing named (one task),
        else the organisation's published pattern of that name.
        """
        called = (element.get("calledElement") or "").strip()
        if not called or self.reading.global_task(called) is not None:
            return _Callee()
        process = self.reading.process_element(called)
        if process is not None:
            if called in self.calling:
                self.reading.fail(
                    f"The {what} calls process {called}, which is already being called on the "
                    "way there: a recursive call cannot be flattened.",
                    element.get("id", ""),
                )
                return None
            return _Callee(process=process)
        names = [called] + ([element.get("name", "")] if element.get("name") else [])
        pattern = self.called(names)
        if pattern is None:
            self.reading.fail(
                f"The {what} calls {called!r}, which is neither a process of this file nor a "
                "published pattern of that name.",
                element.get("id", ""),
            )
            return None
        if len(pattern.processes) != 1:
            self.reading.fail(
                f"The {what} calls the published pattern {pattern.name!r}, which has "
                f"{len(pattern.processes)} processes; a call activity inlines one.",
                element.get("id", ""),
            )
            return None
        return _Callee(pattern=pattern)

    def _compensated(self, handler_id: str) -> str | None:
        """The activity a compensation handler undoes, through its boundary event's association."""
        elements = {e.get("id"): e for e in self.element.iter() if e.get("id")}
        for association in self.element.iter():
            if bpmn_name(association) != "association":
                continue
            if association.get("targetRef") != handler_id:
                continue
            boundary = elements.get(association.get("sourceRef"))
            activity = elements.get(boundary.get("attachedToRef")) if boundary is not None else None
            if activity is not None:
                kind = bpmn_name(activity) or "activity"
                return describe(kind, activity.get("id", ""), activity.get("name"))
        return None

    # Boundary events.

    def _boundary(
        self,
        element: ET.Element,
        scope: Scope,
        prefix: str,
        entry: dict[str, FlowNode],
        exit_: dict[str, FlowNode],
    ) -> FlowNode | None:
        xml_id = element.get("id", "")
        name = (element.get("name") or "").strip() or None
        what = describe("boundaryEvent", xml_id, name)
        attached = element.get("attachedToRef", "")
        if attached in self.refused:
            self.refused.add(xml_id)
            return None
        host = entry.get(attached)
        if host is None:
            self.reading.fail(f"The {what} is attached to {attached!r}, no activity here.", xml_id)
            return None
        node = self._node(
            "boundaryEvent",
            xml_id,
            prefix + self.reading.hrc_id(xml_id),
            name,
            scope,
            self.reading.extra(element, what),
        )
        trigger = self._trigger(element, node)
        if trigger is not None and trigger.kind in ("compensate", "cancel"):
            self.reading.fail(
                f"The {what} starts a {trigger.kind} handler: compensation and cancellation "
                "are not imported.",
                xml_id,
            )
            self.refused.add(xml_id)
            return None
        inner = self._entered_by.get(id(host))
        if inner is None:
            inner = self._task_scope(host)
            entry[attached], exit_[attached] = (
                self.begins[inner.hrc_id],
                self._finishes[inner.hrc_id],
            )
        interrupting = element.get("cancelActivity", "true") != "false"
        node.pre.append(inner.place or "")
        if interrupting:
            node.cancels.append(inner)
        else:
            armed = self.reading.fresh(f"{node.hrc_id}_armed")
            inner.armed.append(armed)
            node.pre.append(armed)
            node.post.append(inner.place or "")
            self.begins[inner.hrc_id].post.append(armed)
        boundary = _Boundary(node, trigger, interrupting, inner)
        self.boundaries.append(boundary)
        self.boundary_of_scope.setdefault(inner.hrc_id, []).append(boundary)
        self._event_keys(node, trigger, catching=True, what=what)
        return node

    def _task_scope(self, task: FlowNode) -> Scope:
        """Wraps a task in a scope of its own, between silent steps: its boundary events' scope."""
        existing = self.graph.scopes.get(task.hrc_id)
        if existing is not None:
            return existing
        begin = self._node(
            "begin", task.xml_id, self.reading.fresh(f"{task.hrc_id}_begins"), task.name, task.scope
        )
        finish = self._node(
            "finish", task.xml_id, self.reading.fresh(f"{task.hrc_id}_ends"), task.name, task.scope
        )
        inner = self._scope(task.hrc_id, task.scope, begin, finish)
        # Flows are read after boundary events: those of the task will reach its steps.
        task.scope = inner
        task.pre.append(inner.source)
        task.post.append(inner.sink)
        return inner

    # Sequence flows.

    def _flows(
        self,
        element: ET.Element,
        scope: Scope,
        prefix: str,
        entry: dict[str, FlowNode],
        exit_: dict[str, FlowNode],
    ) -> None:
        for flow_element in children(element, "sequenceFlow"):
            xml_id = flow_element.get("id", "")
            if not xml_id:
                self.reading.fail(f"A sequence flow in {element.get('id', 'a process')} has no id.")
                continue
            source_ref, target_ref = (
                flow_element.get("sourceRef", ""),
                flow_element.get("targetRef", ""),
            )
            if source_ref in self.refused or target_ref in self.refused:
                continue  # its end was refused, and said so
            source, target = exit_.get(source_ref), entry.get(target_ref)
            name = (flow_element.get("name") or "").strip() or None
            what = describe("sequenceFlow", xml_id, name)
            if source is None or target is None:
                missing = [
                    r or "(nothing)"
                    for r, n in ((source_ref, source), (target_ref, target))
                    if n is None
                ]
                self.reading.fail(
                    f"The {what} names {', '.join(missing)}, which is no flow node here.", xml_id
                )
                continue
            extra = self.reading.extra(flow_element, what)
            if name and "name" not in extra:
                extra = {"name": name, **extra}
            extra.pop("id", None)
            flow = Flow(xml_id, prefix + self.reading.hrc_id(xml_id), source, target, extra, scope)
            self._condition(flow_element, flow, what)
            self.connect(flow)
        self._conditional_flows(scope)

    def connect(self, flow: Flow) -> None:
        flow.source.outgoing.append(flow)
        flow.target.incoming.append(flow)
        self.graph.flows.append(flow)

    def synthetic_flow(self, source: FlowNode, target: FlowNode, scope: Scope) -> Flow:
        flow_id = self.reading.fresh(f"{source.hrc_id}_to_{target.hrc_id}")
        flow = Flow(flow_id, flow_id, source, target, {}, scope)
        self.connect(flow)
        return flow

    def _condition(self, element: ET.Element, flow: Flow, what: str) -> None:
        """The flow's guard; an empty conditionExpression (Bonita writes one on every flow) is none."""
        condition = next(iter(children(element, "conditionExpression")), None)
        text = text_of(condition)
        if condition is None or not text:
            return
        language = condition.get("language") or self.element.get("expressionLanguage")
        guard = translate(text, language)
        if guard is not None:
            flow.guard = guard
        else:
            shown = f" ({language})" if language else ""
            flow.rewrite = (
                f"The condition {text[:200]!r}{shown} of the {what} did not translate into hrc's "
                "expressions: write it as a guard over data."
            )

    def _conditional_flows(self, scope: Scope) -> None:
        """Conditions (or a default flow) on flows out of a task or event: a silent choice after it."""
        for node in [n for n in self.graph.nodes if n.scope is scope]:
            if node.kind in GATEWAY_KINDS:
                continue
            # A default flow only makes sense beside conditional ones, even if theirs were left empty.
            has_default = any(f.xml_id == node.default for f in node.outgoing)
            if not has_default and not any(f.guard or f.rewrite for f in node.outgoing):
                continue
            choice = self._node(
                "exclusiveGateway",
                node.xml_id,
                self.reading.fresh(f"{node.hrc_id}_choice"),
                None,
                scope,
            )
            choice.default = node.default
            moved, node.outgoing = node.outgoing, []
            for flow in moved:
                flow.source = choice
                choice.outgoing.append(flow)
            self.synthetic_flow(node, choice, scope)

    def _implicit_ends(
        self,
        scope: Scope,
        entry: dict[str, FlowNode],
        exit_: dict[str, FlowNode],
        starts: list[FlowNode],
        ends: list[FlowNode],
    ) -> None:
        """Implicit starts and ends: BPMN lets a scope without start events start at its
        nodes with no flow in, and a node with no flow out end its path."""
        nodes = list(dict.fromkeys([*entry.values(), *exit_.values()]))
        if not starts:
            first = [
                n
                for n in dict.fromkeys(entry.values())
                if not n.incoming
                and n.kind not in ("boundaryEvent", "endEvent")
                and not n.pre
                and not (n.kind == "intermediateCatchEvent" and n.keys.get("bpmn") == "link")
            ]
            if first:
                start = self._node(
                    "startEvent",
                    scope.hrc_id,
                    self.reading.fresh(f"{scope.hrc_id}_begin"),
                    None,
                    scope,
                )
                for node in first:
                    self.synthetic_flow(start, node, scope)
                starts.append(start)
        # A node with no flow out ends its path, end events or not (BPMN's implicit end).
        last = [
            n
            for n in nodes
            if not n.outgoing
            and n.kind != "endEvent"
            and not n.post
            and not (n.kind == "intermediateThrowEvent" and n.keys.get("bpmn") == "link")
        ]
        if last:
            end = self._node(
                "endEvent",
                scope.hrc_id,
                self.reading.fresh(f"{scope.hrc_id}_complete"),
                None,
                scope,
            )
            for node in last:
                self.synthetic_flow(node, end, scope)
            ends.append(end)

    # Events.

    def _trigger(self, element: ET.Element, node: FlowNode) -> Trigger | None:
        for given in element:
            child = given
            if bpmn_name(given) == "eventDefinitionRef":
                # A definition at the file's root, shared by several events.
                shared = self.reading.event_definition(text_of(given))
                if shared is None:
                    return Trigger("reference", given, text_of(given))
                child = shared
            local = bpmn_name(child) or ""
            if local.endswith("EventDefinition"):
                kind = local.removesuffix("EventDefinition")
                reference = (
                    child.get("messageRef")
                    or child.get("signalRef")
                    or child.get("errorRef")
                    or child.get("escalationRef")
                )
                name = self.reading.definition_name(reference)
                if kind == "link":
                    name = child.get("name") or node.name
                return Trigger(kind, child, name)
        return None

    def _event(self, element: ET.Element, node: FlowNode) -> bool:
        """Sets the keys an event's trigger gives its transition; False once refused."""
        trigger = self._trigger(element, node)
        what = node.describe()
        if trigger is None:
            return True
        if trigger.kind == "reference":
            self.reading.fail(
                f"The {what} refers to event definition {trigger.name!r}, which this file does "
                "not define.",
                node.xml_id,
            )
            return False
        if trigger.kind in ("compensate", "cancel"):
            self.reading.fail(
                f"The {what} has a {trigger.kind} event definition: compensation and "
                "cancellation are not imported.",
                node.xml_id,
            )
            return False
        catching = node.kind in ("startEvent", "intermediateCatchEvent")
        if trigger.kind == "link":
            node.keys["bpmn"] = "link"
            self.links.append((node, trigger.name or "", catching))
            return True
        if node.kind == "endEvent" and trigger.kind == "terminate":
            node.cancels.append(node.scope)
            node.keys["bpmn"] = "terminate"
            return True
        if node.kind in ("endEvent", "intermediateThrowEvent") and trigger.kind in (
            "error",
            "escalation",
        ):
            self.throwers.append((node, trigger))
        self._event_keys(node, trigger, catching=catching, what=what)
        return True

    def _event_keys(
        self, node: FlowNode, trigger: Trigger | None, *, catching: bool, what: str
    ) -> None:
        if trigger is None:
            return
        kind = trigger.kind
        keys: Json = {}
        if kind == "message":
            if catching:
                name = self.reading.message_in(node.xml_id)
                if node.kind == "startEvent" and name is None:
                    keys["bpmn"] = "message start"
                else:
                    keys["message"] = _awaited(name or trigger.name or node.name or node.xml_id)
            else:
                sent = self.reading.messages_out(node.xml_id)
                keys["send"] = _sent(sent[0] if sent else trigger.name or node.name or node.xml_id)
        elif kind == "signal":
            name = f"signal:{trigger.name or node.name or node.xml_id}"
            if not catching:
                keys["send"] = _sent(name)
            elif node.kind == "startEvent" and not self.reading.signal_thrown(name):
                keys["bpmn"] = "signal start"
            else:
                keys["message"] = _awaited(name)
        elif kind == "timer":
            keys.update(self._timer(trigger.element, node, what))
        elif kind == "conditional":
            condition = next(iter(children(trigger.element, "condition")), None)
            text = text_of(condition)
            guard = translate(text, condition.get("language") if condition is not None else None)
            if node.kind == "startEvent":
                keys["bpmn"] = "conditional start"
            elif guard is not None:
                keys["guard"] = guard
            else:
                keys["rewrite"] = (
                    f"The condition {text[:200]!r} of the {what} did not translate into hrc's "
                    "expressions: write it as a guard over data."
                )
        elif kind in ("error", "escalation") and node.kind == "boundaryEvent":
            keys["message"] = _awaited(f"{kind}:{trigger.name or node.name or node.xml_id}")
        elif kind in ("error", "escalation") and catching:
            keys["bpmn"] = f"{kind} start"
        sent_extra = self.reading.messages_out(node.xml_id)
        if not catching and "send" not in keys and sent_extra:
            keys["send"] = _sent(sent_extra[0])
        node.keys.update(keys)

    def _timer(self, definition: ET.Element, node: FlowNode, what: str) -> Json:
        duration = text_of(next(iter(children(definition, "timeDuration")), None))
        if node.kind == "startEvent":
            return {"bpmn": "timer start"}
        if duration and DURATION.match(duration):
            return {"timer": duration}
        given = next(
            (
                f"{c.tag.split('}')[-1]} {text_of(c)!r}"
                for c in definition
                if bpmn_name(c) in ("timeDuration", "timeDate", "timeCycle")
            ),
            "no time",
        )
        return {
            "rewrite": f"The {what} waits for {given[:200]}: hrc's timers wait a fixed duration "
            "(such as PT5M); give it one."
        }

    def _task_messages(self, node: FlowNode) -> None:
        received = self.reading.message_in(node.xml_id)
        if received is not None:
            node.receive = _awaited(received)
        sent = self.reading.messages_out(node.xml_id)
        if sent:
            node.keys.setdefault("send", _sent(sent[0]))

    # Loops and multi-instance activities.

    def _loops(self, element: ET.Element, node: FlowNode) -> None:
        what = node.describe()
        loop = next(iter(children(element, "standardLoopCharacteristics")), None)
        if loop is not None:
            condition = next(iter(children(loop, "loopCondition")), None)
            text = text_of(condition)
            guard = (
                translate(text, condition.get("language") if condition is not None else None)
                if text
                else None
            )
            if guard is not None:
                node.loop = {"guard": guard}
            else:
                node.loop = {
                    "rewrite": f"The {what} loops "
                    + (
                        f"while {text[:200]!r}, which did not translate"
                        if text
                        else "without a condition"
                    )
                    + ": write the guard of repeating it."
                }
        multiple = next(iter(children(element, "multiInstanceLoopCharacteristics")), None)
        if multiple is None:
            return
        cardinality = text_of(next(iter(children(multiple, "loopCardinality")), None))
        sequential = multiple.get("isSequential") == "true"
        if cardinality.isdigit() and 1 <= int(cardinality) <= MAX_COPIES and node.kind != "begin":
            node.copies = (int(cardinality), sequential)
            return
        collection = next((v for k, v in multiple.attrib.items() if k.endswith("collection")), None)
        if cardinality:
            how = f"{cardinality[:200]!r} times"
        elif collection:
            how = f"once per item of {collection[:200]!r}"
        else:
            how = "a number of times known only at run time"
        node.keys["rewrite"] = (
            f"The {what} runs {how} ({'in sequence' if sequential else 'in parallel'}): it is "
            "imported once; draw its copies."
        )

    # After the whole process is read.

    def _route_throws(self) -> None:
        """Error and escalation events thrown inside an activity go to the boundary that catches them."""
        for thrower, trigger in self.throwers:
            boundary = self._catcher(thrower.scope, trigger)
            if boundary is None:
                if thrower.kind == "endEvent" and trigger.kind == "error":
                    # An uncaught error ends the whole process, like a terminate end event.
                    thrower.cancels.append(self.graph.root)
                    if thrower.scope is not self.graph.root:
                        thrower.to_sink = self.graph.root
                continue
            boundary.caught = True
            if boundary.interrupting and thrower.kind == "endEvent":
                thrower.pre.append(boundary.scope.place or "")
                thrower.cancels.append(boundary.scope)
                thrower.post_flows = boundary.node.outgoing
                thrower.routed = True
            else:
                thrower.post_flows = boundary.node.outgoing
        for boundary in self.boundaries:
            if (
                boundary.caught
                and boundary.trigger is not None
                and boundary.trigger.kind in ("error", "escalation")
            ):
                boundary.node.keys.pop("message", None)
                boundary.node.kind = "caughtBoundaryEvent"

    def _catcher(self, scope: Scope, trigger: Trigger) -> "_Boundary | None":
        for enclosing in scope.chain():
            for boundary in self.boundary_of_scope.get(enclosing.hrc_id, []):
                caught = boundary.trigger
                if caught is None or caught.kind != trigger.kind:
                    continue
                if caught.name is None or trigger.name is None or caught.name == trigger.name:
                    return boundary
        return None

    def _links(self) -> None:
        """A link throw event jumps to the catch event of the same name."""
        catches = {name: node for node, name, catching in self.links if catching}
        for node, name, catching in self.links:
            if catching:
                continue
            target = catches.get(name)
            if target is None:
                self.reading.fail(
                    f"The {node.describe()} jumps to link {name!r}, which no catch event names.",
                    node.xml_id,
                )
                continue
            self.synthetic_flow(node, target, node.scope)

    def _inclusive_blocks(self) -> None:
        """Finds each inclusive split's join: the inclusive gateway every branch reaches first."""
        joins = {
            n.xml_id
            for n in self.graph.nodes
            if n.kind == "inclusiveGateway" and len(n.incoming) > 1
        }
        claimed: set[str] = set()
        for split in [
            n for n in self.graph.nodes if n.kind == "inclusiveGateway" and len(n.outgoing) > 1
        ]:
            if len(split.incoming) > 1:
                self.reading.fail(
                    f"The {split.describe()} both joins and splits: draw an inclusive join and "
                    "a separate inclusive split.",
                    split.xml_id,
                )
                continue
            if len(split.outgoing) > MAX_INCLUSIVE_BRANCHES:
                self.reading.fail(
                    f"The {split.describe()} has {len(split.outgoing)} branches; inclusive "
                    f"gateways are imported with at most {MAX_INCLUSIVE_BRANCHES}.",
                    split.xml_id,
                )
                continue
            reached = [_reach(flow, joins) for flow in split.outgoing]
            common = set.intersection(*[set(r) for r in reached]) if reached else set()
            if not any(reached):
                continue  # the branches never meet again: no join to tell
            candidates = [j for j in reached[0] if j in common]
            join = next(
                (n for n in self.graph.nodes if candidates and n.xml_id == candidates[0]), None
            )
            mapping = self._branch_flows(split, join) if join is not None else None
            if join is None or mapping is None:
                self.reading.fail(
                    f"The {split.describe()} splits into branches that do not all meet again at "
                    "one inclusive gateway, one flow each: hrc imports inclusive gateways that "
                    "form a block.",
                    split.xml_id,
                )
                continue
            split.inclusive_join = join
            split.branch_flows = mapping
            claimed.add(join.xml_id)
        for join in [n for n in self.graph.nodes if n.xml_id in joins and n.xml_id not in claimed]:
            if len(join.outgoing) <= 1 and join.xml_id not in self.refused:
                self.reading.fail(
                    f"The {join.describe()} merges branches no inclusive split of the same "
                    "block started: hrc imports inclusive gateways that form a block.",
                    join.xml_id,
                )

    def _branch_flows(self, split: FlowNode, join: FlowNode) -> dict[str, str] | None:
        mapping: dict[str, str] = {}
        for flow in split.outgoing:
            arrivals = _arrivals(flow, join)
            if len(arrivals) != 1:
                return None
            mapping[flow.xml_id] = arrivals[0].place
        if len(set(mapping.values())) != len(join.incoming):
            return None
        return mapping


@dataclass
class _Callee:
    """What a call activity calls: a process of the file, a published pattern, or neither (a task)."""

    process: ET.Element | None = None
    pattern: Pattern | None = None


def _awaited(name: str) -> Json:
    return {"name": name, "correlation": dict(CORRELATION_AWAIT)}


def _sent(name: str) -> Json:
    return {"name": name, "correlation": dict(CORRELATION_SEND)}


def _reach(flow: Flow, joins: set[str]) -> list[str]:
    """The joins reachable from the flow without passing another, nearest first."""
    seen: set[int] = set()
    found: list[str] = []
    frontier = [flow]
    while frontier:
        following: list[Flow] = []
        for current in frontier:
            if id(current) in seen:
                continue
            seen.add(id(current))
            target = current.target
            if target.xml_id in joins:
                if target.xml_id not in found:
                    found.append(target.xml_id)
                continue
            following += target.outgoing
        frontier = following
    return found


def _arrivals(flow: Flow, join: FlowNode) -> list[Flow]:
    """The join's incoming flows reachable from the flow."""
    seen: set[int] = set()
    arrivals: list[Flow] = []
    stack = [flow]
    while stack:
        current = stack.pop()
        if id(current) in seen:
            continue
        seen.add(id(current))
        if current.target is join:
            if current not in arrivals:
                arrivals.append(current)
            continue
        stack += current.target.outgoing
    return arrivals
