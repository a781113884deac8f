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
from typing import Any

from hrc.engine.bpmn_conditions import compared_values, data_defaults, translate
from hrc.engine.bpmn_events import (
    Reading,
    Trigger,
    event_keys,
    task_messages,
    trigger_of,
)
from hrc.engine.bpmn_gateways import deferred_choices, inclusive_blocks
from hrc.engine.bpmn_loops import mark_loops
from hrc.engine.bpmn_net import (
    EVENT_KINDS,
    GATEWAY_KINDS,
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
    data: dict[str, object] = field(default_factory=dict)
    """The case data its translated conditions read, with defaults (`bpmn_conditions.data_defaults`)."""
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
        inclusive_blocks(self.graph.nodes, self.reading.fail)
        deferred_choices(self.graph.nodes)
        for node in self.graph.nodes:  # conditional events and loops: always another engine's
            for guard in (node.keys.get("guard"), (node.loop or {}).get("guard")):
                if isinstance(guard, str):
                    for key, value in data_defaults(guard).items():
                        self.graph.data.setdefault(key, value)
        self._answers()
        return self.graph

    def _written(self, task: ET.Element) -> list[str]:
        """The names of the task's data outputs and of the data objects it writes."""
        objects = {
            child.get("id"): child.get("name")
            for child in self.element.iter()
            if bpmn_name(child) in ("dataObject", "dataObjectReference")
        }
        names = [
            output.get("name")
            for spec in task
            if bpmn_name(spec) == "ioSpecification"
            for output in spec
            if bpmn_name(output) == "dataOutput"
        ]
        for association in task:
            if bpmn_name(association) == "dataOutputAssociation":
                names += [
                    objects.get((target.text or "").strip())
                    for target in association
                    if bpmn_name(target) == "targetRef"
                ]
        return [n for n in dict.fromkeys(names) if n and _DATA_NAME.fullmatch(n)]

    def _answers(self) -> None:
        """A task that writes data a condition reads asks for it (a form), and its answer goes
        into the case data: in BPMN the approver's form sets `approved`, which the gateway after
        the task reads; without it the case would keep the default and never take the other way.
        A field the conditions compare with strings offers those strings."""
        compared: dict[str, list[object]] = {}
        for flow in self.graph.flows:
            for key, values in compared_values(flow.guard or "True").items():
                compared.setdefault(key, [])
                compared[key] += [v for v in values if v not in compared[key]]
        for node in self.graph.nodes:
            asked = [key for key in node.writes if key in self.graph.data]
            if not asked or "task" in node.extra or "task" in node.keys:
                continue
            fields = {key: _field(self.graph.data[key], compared.get(key, [])) for key in asked}
            node.keys["task"] = {
                "form": {"type": "object", "properties": fields, "required": asked},
                "outputs": {key: f"result.{key}" for key in asked},
            }

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
            task_messages(self.reading, node, element.get("messageRef"))
            node.writes = self._written(element)
            mark_loops(element, node)
        elif local in EVENT_KINDS and not self._event(element, node):
            self.refused.add(xml_id)
            return None
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
            task_messages(self.reading, node, element.get("messageRef"))
            mark_loops(element, node)
            return node, node
        begin = self._node("begin", xml_id, hrc_id, name, scope, self.reading.extra(element, what))
        finish = self._node("finish", xml_id, self.reading.fresh(f"{hrc_id}_ends"), name, scope)
        inner = self._scope(hrc_id, scope, begin, finish)
        mark_loops(element, begin)
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
        kind = trigger_of(self.reading, start, self._node("startEvent", "", "", None, host))
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
        trigger = trigger_of(self.reading, start, catch)
        catch.pre.append(host.place)
        catch.cancels.append(host)
        boundary = _Boundary(catch, trigger, True, host)
        self.boundaries.append(boundary)
        self.boundary_of_scope.setdefault(host.hrc_id, []).append(boundary)
        event_keys(self.reading, catch, trigger, catching=True, what=what)
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
                    f"The {what} calls process {called}, which is calling it already: a "
                    "recursive call cannot be flattened into one net.",
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
        trigger = trigger_of(self.reading, element, node)
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
        event_keys(self.reading, node, trigger, catching=True, what=what)
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
            if guard != text.strip():  # written for another engine: its variables start empty
                for key, value in data_defaults(guard).items():
                    self.graph.data.setdefault(key, value)
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
            first = self._unreached(entry)
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
        else:
            # Beside start events BPMN never starts a node no flow enters (a flow lost in an
            # export, say): it waits on a place no token ever reaches, so the check finds it dead.
            for node in self._unreached(entry):
                source = self._node(
                    "unreached",
                    node.xml_id,
                    self.reading.fresh(f"{node.hrc_id}_unreached"),
                    None,
                    scope,
                )
                flow = self.synthetic_flow(source, node, scope)
                flow.extra = {"tokens": 0, "name": f"nothing reaches the {node.describe()}"}
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

    @staticmethod
    def _unreached(entry: dict[str, FlowNode]) -> list[FlowNode]:
        """The nodes no flow enters that BPMN would start only in a scope without start events."""
        return [
            n
            for n in dict.fromkeys(entry.values())
            if not n.incoming
            and n.kind not in ("startEvent", "boundaryEvent", "endEvent")
            and not n.pre
            and not (n.kind == "intermediateCatchEvent" and n.keys.get("bpmn") == "link")
        ]

    # Events.

    def _event(self, element: ET.Element, node: FlowNode) -> bool:
        """Sets the keys an event's trigger gives its transition; False once refused."""
        trigger = trigger_of(self.reading, element, node)
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
        event_keys(self.reading, node, trigger, catching=catching, what=what)
        return True

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


@dataclass
class _Callee:
    """What a call activity calls: a process of the file, a published pattern, or neither (a task)."""

    process: ET.Element | None = None
    pattern: Pattern | None = None


_DATA_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")


def _field(default: object, compared: list[object]) -> Json:
    """The form field for a data key: of its default's type, offering the strings compared."""
    if isinstance(default, bool) or default is None:
        return {"type": "boolean"}
    if isinstance(default, int | float):
        return {"type": "number"}
    strings = [value for value in compared if isinstance(value, str)]
    return {"type": "string", **({"enum": strings} if strings else {})}
