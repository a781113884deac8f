"""BPMN 2.0 import into collaboration patterns, following Dijkman, Dumas and Ouyang (2008).

`bpmn_to_pattern` reads the process models of a BPMN 2.0 XML file (its
`<process>` elements, pools and lanes) and builds an `hrc-pattern/1` document
with the mapping of R. M. Dijkman, M. Dumas, C. Ouyang, "Semantics and analysis
of business process models in BPMN", Information and Software Technology 50
(2008), figure 3, where every sequence flow is a place:

| BPMN | hrc-pattern/1 |
| --- | --- |
| sequence flow f | place f (its name in the place's `name`) |
| task T (task, userTask, manualTask, serviceTask, scriptTask, businessRuleTask, sendTask, receiveTask) | transition T performed by its lane's actor, labelled with its name (a kind other than `task` kept in its `bpmn` key); arcs from its incoming and to its outgoing flows' places. Several incoming flows merge first (the paper's normalisation: an exclusive merge, a silent transition per flow into a place `T_in`); several outgoing flows all get a token (a parallel split) |
| none intermediate event E | silent transition E, with the same arcs as a task |
| start event S | the net's source place: S itself when the process has one start event, each start event then fires through a silent transition into its outgoing flows. With several start events the source place is `<process>_start` and each start event is a silent transition S out of it (an instance starts at one of them) |
| end event E | the net's sink place, in the same way: E when there is one, else `<process>_end`; every incoming flow reaches it through a silent transition |
| parallel gateway G (fork, join, or both) | one silent transition G consuming all incoming and producing all outgoing flows |
| exclusive gateway G | a place where the choice or merge happens, with a silent transition per branch: a split keeps its incoming flow's place and gets a transition `G_<flow>` into each outgoing flow's place (the flow's condition becomes that transition's `guard`; the default flow's is "none of the others"); a merge gets a transition per incoming flow into the outgoing flow's place; a gateway with several of each gets its own place G between them |
| lane | an actor (id: the lane's id), performing the tasks in it (the innermost lane when lanes nest); lanes without tasks are left out |
| pool without lanes | one actor: the participant, or `<process>_actor` |
| process | a process of the pattern (several pools: several processes, as in Coexistence); its workpiece is its `hrc:workpiece` attribute, else the name of its pool, else its own name or id (wpassign is total) |

Actor type: the lane's `hrc:actorType` attribute (`cobot` or `operator`),
else `cobot` when the lane's name (or id) contains "cobot" or "robot" (any
case), else `operator`. Constraints are associations between two tasks with
an `hrc:constraint` attribute (`time`, `space`, `func`); other associations,
text annotations, groups and data objects are ignored. `hrc` is the namespace
HRC_NAMESPACE; an `<hrc:extra>` element in an element's extensionElements
holds, as a JSON object, the keys of its `hrc-pattern/1` object the BPMN part
does not carry (task configuration, an id XML cannot hold, ...), and overrides
it on import: that is how our own exports come back with everything.

What the mapping does not cover is refused with a FormatError that names the
element: inclusive, complex and event-based gateways, subprocesses and call
activities, boundary events, events with a definition (timer, message, ...),
loop and multi-instance tasks, message flows, choreographies and
conversations, and conditions on flows out of anything but an exclusive
gateway. Nothing else is read from the file, so a refused import creates
nothing. Positions (BPMNDI) are not read: `layout.lay_out` draws the pattern in
its actors' lanes.

Exclusive gateways choose when they are reached (BPMN's data-based choice),
not when a task starts: a round trip through `pattern_to_bpmn` keeps the tasks,
actors, constraints and every sequence of task starts and completions, but a
choice between two tasks is then made by a silent step just before them.
"""

import json
import re
import xml.etree.ElementTree as ET
from collections.abc import Iterator
from io import BytesIO
from typing import Any, cast

from defusedxml import (  # type: ignore[import-untyped, unused-ignore]
    DefusedXmlException,
)
from defusedxml.ElementTree import (  # type: ignore[import-untyped, unused-ignore]
    iterparse as _safe_iterparse,
)

from hrc.engine.bpmn_net import EVENT_KINDS, GATEWAY_KINDS, TASK_KINDS, Flow, FlowNet, FlowNode
from hrc.engine.document import FORMAT, FormatError, read_pattern
from hrc.engine.issues import Issue, error
from hrc.engine.model import Pattern
from hrc.engine.pnml import parse_xml

BPMN_NAMESPACE = "http://www.omg.org/spec/BPMN/20100524/MODEL"
BPMNDI_NAMESPACE = "http://www.omg.org/spec/BPMN/20100524/DI"
DC_NAMESPACE = "http://www.omg.org/spec/DD/20100524/DC"
DI_NAMESPACE = "http://www.omg.org/spec/DD/20100524/DI"
HRC_NAMESPACE = "urn:hrc:bpmn:1"
"""Our attributes (actorType, constraint, workpiece, declaredPattern) and the `extra` element."""

Json = dict[str, Any]

FLOW_NODE_KINDS = TASK_KINDS | GATEWAY_KINDS | EVENT_KINDS
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
    }
)
ROOT_REFUSED = frozenset(
    {"choreography", "globalChoreographyTask", "globalConversation", "globalTask"}
)
COLLABORATION_IGNORED = frozenset(
    {"documentation", "extensionElements", "participant", "association", "textAnnotation", "group"}
)
REFUSED_WHY = {
    "inclusiveGateway": "an inclusive (OR) gateway has no Petri net mapping in hrc",
    "complexGateway": "a complex gateway has no Petri net mapping in hrc",
    "eventBasedGateway": "an event-based gateway waits for events hrc does not model",
    "subProcess": "subprocesses are not mapped: draw its tasks in the process",
    "adHocSubProcess": "ad-hoc subprocesses are not mapped",
    "transaction": "transactions are not mapped",
    "callActivity": "call activities are not mapped: draw the called tasks in the process",
    "boundaryEvent": "boundary events (exceptions) are not mapped",
    "messageFlow": "message flows between pools are not mapped",
}
COBOT_NAME = re.compile(r"cobot|robot", re.IGNORECASE)


def bpmn_to_pattern(text: str | bytes) -> Pattern:
    """Reads a BPMN 2.0 file; raises FormatError, naming the element, when it cannot.

    DTDs are refused, so no entity can expand or reach outside the text.
    """
    return read_pattern(bpmn_to_document(text))


def bpmn_to_document(text: str | bytes) -> Json:
    """The `hrc-pattern/1` document of a BPMN file, before `read_pattern` checks its shape."""
    return _Importer(parse_xml(text, "BPMN")).document()


def is_bpmn(text: str | bytes) -> bool:
    """Whether the text's root element is BPMN's `<definitions>`; reads no further than that.

    Unreadable or hostile text is not BPMN here: whoever reads it next refuses it.
    """
    data = text.encode() if isinstance(text, str) else text
    try:
        for _, element in _safe_iterparse(
            BytesIO(data),
            events=("start",),
            forbid_dtd=True,
            forbid_entities=True,
            forbid_external=True,
        ):
            return bool(element.tag == f"{{{BPMN_NAMESPACE}}}definitions")
    except (DefusedXmlException, ET.ParseError, UnicodeError, LookupError, ValueError):
        return False
    return False


def _refuse(message: str, *elements: str) -> FormatError:
    return FormatError([error("format", message, *elements)])


def _local(element: ET.Element) -> tuple[str, str]:
    """(namespace, local name) of an element; comments and processing instructions have none."""
    tag = element.tag
    if not isinstance(tag, str):
        return ("", "")
    if tag.startswith("{"):
        namespace, _, local = tag[1:].partition("}")
        return namespace, local
    return "", tag


def _bpmn(element: ET.Element) -> str | None:
    """The local name of a BPMN element; None for elements of other namespaces."""
    namespace, local = _local(element)
    return local if namespace == BPMN_NAMESPACE else None


def _children(element: ET.Element, local: str) -> list[ET.Element]:
    tag = f"{{{BPMN_NAMESPACE}}}{local}"
    return [child for child in element if child.tag == tag]


def _hrc(element: ET.Element, name: str) -> str | None:
    return element.get(f"{{{HRC_NAMESPACE}}}{name}")


def _workpiece(process: ET.Element, pool: ET.Element | None, process_id: str) -> str:
    """What the process works on: ours as exported, else named after its pool or itself."""
    candidates = [
        _hrc(process, "workpiece"),
        pool.get("name") if pool is not None else None,
        process.get("name"),
    ]
    return next((c.strip() for c in candidates if c and c.strip()), process_id)


class _Importer:
    """Turns a BPMN tree into an `hrc-pattern/1` document, collecting every refusal."""

    def __init__(self, root: ET.Element) -> None:
        self.root = root
        self.issues: list[Issue] = []
        self.taken: set[str] = set()
        self.actors: dict[str, Json] = {}
        self.constraints: list[Json] = []
        self.hrc_ids: dict[str, str] = {}
        """XML id -> hrc id of every element that has one."""

    def fail(self, message: str, *elements: str) -> None:
        self.issues.append(error("format", message, *elements))

    def document(self) -> Json:
        namespace, local = _local(self.root)
        if (namespace, local) != (BPMN_NAMESPACE, "definitions"):
            shown = f"<{local}> in namespace {namespace!r}" if namespace else f"<{local}>"
            raise _refuse(
                f"The root element is {shown}, not BPMN's <definitions> in {BPMN_NAMESPACE!r}:"
                " this is not a BPMN 2.0 file."
            )
        self._collect_ids()
        processes, collaborations = self._root_elements()
        participants = self._participants(collaborations)
        document: Json = {"format": FORMAT, "name": self._name(processes, participants)}
        declared = _hrc(self.root, "declaredPattern")
        if declared is not None:
            document["declared_pattern"] = declared
        order: list[object] = []
        for collaboration in collaborations:
            extra = self._extra(collaboration, f"collaboration {collaboration.get('id')}")
            # Our export lists the actors' ids here, in the document's order.
            listed = extra.pop("actors", [])
            order += listed if isinstance(listed, list) else []
            document.update(extra)
        built = [self._process(p, participants.get(p.get("id", ""))) for p in processes]
        for container in [*processes, *collaborations]:
            self._constraints(container)
        if not self.issues and not built:
            self.fail(
                "The file has no process with flow nodes (events, tasks, gateways) to import."
            )
        if self.issues:
            raise FormatError(list(dict.fromkeys(self.issues)))
        rank = {actor_id: index for index, actor_id in reversed(list(enumerate(order)))}
        document["actors"] = sorted(
            self.actors.values(), key=lambda actor: rank.get(actor["id"], len(rank))
        )
        document["processes"] = built
        document["constraints"] = self.constraints
        return document

    # Ids.

    def _collect_ids(self) -> None:
        """Every XML id, and the hrc id its `hrc:extra` gives, so fresh ids never collide."""
        for element in self.root.iter():
            xml_id = element.get("id")
            if xml_id:
                self.taken.add(xml_id)
                self.hrc_ids[xml_id] = xml_id
        for element in self.root.iter():
            xml_id = element.get("id")
            if xml_id and _bpmn(element) is not None:
                given = self._extra(element, f"element {xml_id}").get("id")
                if isinstance(given, str) and given:
                    self.hrc_ids[xml_id] = given
                    self.taken.add(given)

    def fresh(self, base: str) -> str:
        """A new id from `base`: base itself if free, else base_2, base_3, ..."""
        candidate, number = base, 1
        while candidate in self.taken:
            number += 1
            candidate = f"{base}_{number}"
        self.taken.add(candidate)
        return candidate

    def _extra(self, element: ET.Element, where: str) -> Json:
        """The JSON object in the element's `<hrc:extra>`; {} (and an issue if broken) if none."""
        holder = next(iter(_children(element, "extensionElements")), None)
        if holder is None:
            return {}
        blocks = [child for child in holder if child.tag == f"{{{HRC_NAMESPACE}}}extra"]
        if not blocks:
            return {}
        xml_id = element.get("id", "")
        ids = [xml_id] if xml_id else []
        if len(blocks) > 1:
            self.fail(f"The {where} has {len(blocks)} hrc:extra elements; one is allowed.", *ids)
            return {}
        try:
            data = cast(object, json.loads(blocks[0].text or ""))
        except (ValueError, RecursionError):
            self.fail(f"The hrc:extra of the {where} is not JSON.", *ids)
            return {}
        if not isinstance(data, dict):
            self.fail(f"The hrc:extra of the {where} must be a JSON object.", *ids)
            return {}
        return cast(Json, data)

    # The file's root elements.

    def _root_elements(self) -> tuple[list[ET.Element], list[ET.Element]]:
        processes, collaborations = [], []
        for child in self.root:
            local = _bpmn(child)
            if local == "process":
                if any(_bpmn(node) in FLOW_NODE_KINDS | set(REFUSED_WHY) for node in child):
                    processes.append(child)
            elif local == "collaboration":
                collaborations.append(child)
            elif local in ROOT_REFUSED or (local or "").startswith(
                ("choreography", "conversation")
            ):
                self.fail(
                    f"The <{local}> {child.get('id', '')} is not mapped: hrc imports processes, "
                    "pools and lanes.",
                    *([child.get("id", "")] if child.get("id") else []),
                )
        return processes, collaborations

    def _participants(self, collaborations: list[ET.Element]) -> dict[str, ET.Element]:
        """Process id -> its participant (pool); refuses what a collaboration holds beyond pools."""
        participants: dict[str, ET.Element] = {}
        for collaboration in collaborations:
            for child in collaboration:
                local = _bpmn(child)
                if local is None or local in COLLABORATION_IGNORED:
                    if local == "participant" and child.get("processRef"):
                        participants.setdefault(child.get("processRef", ""), child)
                    continue
                self._refuse_element(child, local)
        return participants

    def _refuse_element(self, element: ET.Element, local: str) -> None:
        xml_id = element.get("id", "")
        why = REFUSED_WHY.get(local, "hrc does not map this BPMN element")
        self.fail(
            f"The <{local}> {xml_id or '(without id)'} cannot be imported: {why}.",
            *([xml_id] if xml_id else []),
        )

    def _name(self, processes: list[ET.Element], participants: dict[str, ET.Element]) -> str:
        candidates = [self.root.get("name")]
        for process in processes:
            pool = participants.get(process.get("id", ""))
            candidates += [process.get("name"), pool.get("name") if pool is not None else None]
        return next((c.strip() for c in candidates if c and c.strip()), "Imported BPMN model")

    # One process.

    def _process(self, element: ET.Element, pool: ET.Element | None) -> Json:
        process_xml_id = element.get("id", "")
        if not process_xml_id:
            self.fail("A <process> has no id; BPMN needs one on every process.")
        process_id = self.hrc_ids.get(process_xml_id, process_xml_id)
        nodes = self._flow_nodes(element)
        flows = self._flows(element, nodes)
        net = FlowNet(self.fresh, process_id, flows)
        for node in nodes.values():
            self._check_flows(node)
        lanes = self._lanes(element, nodes, pool, process_id)
        for node in nodes.values():
            net.add(node, lanes.get(node.xml_id))
        net.ends([n for n in nodes.values() if n.kind == "startEvent"], start=True)
        net.ends([n for n in nodes.values() if n.kind == "endEvent"], start=False)
        if not any(n.kind == "startEvent" for n in nodes.values()):
            self.fail(
                f"Process {process_xml_id} has no start event; hrc maps a start event to the "
                "net's source place.",
                process_xml_id,
            )
        if not any(n.kind == "endEvent" for n in nodes.values()):
            self.fail(
                f"Process {process_xml_id} has no end event; hrc maps an end event to the net's "
                "sink place.",
                process_xml_id,
            )
        data: Json = {"id": process_id, "workpiece": _workpiece(element, pool, process_id)}
        data["actors"] = list(dict.fromkeys(lanes.values()))
        if element.get("name"):
            data["name"] = element.get("name")
        data.update(
            {
                k: v
                for k, v in self._extra(element, f"process {process_xml_id}").items()
                if k != "id"
            }
        )
        data["places"] = net.places
        data["transitions"] = net.transitions
        data["arcs"] = net.arcs
        return data

    def _flow_nodes(self, process: ET.Element) -> dict[str, FlowNode]:
        nodes: dict[str, FlowNode] = {}
        process_id = process.get("id", "")
        for child in process:
            local = _bpmn(child)
            if local is None or local in PROCESS_IGNORED:
                continue
            if local not in FLOW_NODE_KINDS:
                self._refuse_element(child, local)
                continue
            xml_id = child.get("id", "")
            if not xml_id:
                self.fail(f"A <{local}> in process {process_id} has no id.", process_id)
                continue
            node = FlowNode(
                local,
                xml_id,
                self.hrc_ids.get(xml_id, xml_id),
                child.get("name") or None,
                {},
                child.get("default"),
            )
            node.extra = self._extra(child, node.describe())
            self._check_contents(child, node)
            nodes[xml_id] = node
        return nodes

    def _flows(self, process: ET.Element, nodes: dict[str, FlowNode]) -> list[Flow]:
        flows = []
        for element in _children(process, "sequenceFlow"):
            xml_id = element.get("id", "")
            if not xml_id:
                self.fail(f"A <sequenceFlow> in process {process.get('id')} has no id.")
                continue
            ends = [nodes.get(element.get(ref, "")) for ref in ("sourceRef", "targetRef")]
            source, target = ends
            if source is None or target is None:
                missing = [
                    element.get(ref) or "(nothing)"
                    for ref, end in zip(("sourceRef", "targetRef"), ends, strict=True)
                    if end is None
                ]
                self.fail(
                    f"Sequence flow {xml_id} names {', '.join(missing)}, which is no flow node of "
                    f"process {process.get('id')}.",
                    xml_id,
                )
                continue
            extra = self._extra(element, f"sequence flow {xml_id}")
            if element.get("name") and "name" not in extra:
                extra = {"name": element.get("name"), **extra}
            extra.pop("id", None)
            condition = next(iter(_children(element, "conditionExpression")), None)
            text = None if condition is None else (condition.text or "").strip() or None
            flow = Flow(xml_id, self.hrc_ids.get(xml_id, xml_id), source, target, extra, text)
            if condition is not None and source.kind != "exclusiveGateway":
                self.fail(
                    f"Sequence flow {xml_id} has a condition but leaves {source.describe()}; "
                    "conditions are mapped only on flows out of an exclusive gateway.",
                    xml_id,
                )
            source.outgoing.append(flow)
            target.incoming.append(flow)
            flows.append(flow)
        return flows

    def _check_contents(self, element: ET.Element, node: FlowNode) -> None:
        """Refuses what the mapping does not cover inside a flow node."""
        for child in element:
            local = _bpmn(child) or ""
            if local.endswith("EventDefinition") or local == "eventDefinitionRef":
                self.fail(
                    f"The {node.describe()} has a {local}; only none events (without a "
                    "definition) are mapped.",
                    node.xml_id,
                )
            elif local in ("standardLoopCharacteristics", "multiInstanceLoopCharacteristics"):
                self.fail(
                    f"The {node.describe()} has {local}; loop and multi-instance tasks are not "
                    "mapped: draw the loop with an exclusive gateway.",
                    node.xml_id,
                )

    def _check_flows(self, node: FlowNode) -> None:
        if node.kind == "startEvent" and node.incoming:
            self.fail(f"Start event {node.xml_id} has an incoming sequence flow.", node.xml_id)
        if node.kind == "endEvent" and node.outgoing:
            self.fail(f"End event {node.xml_id} has an outgoing sequence flow.", node.xml_id)

    # Lanes and actors.

    def _lanes(
        self,
        process: ET.Element,
        nodes: dict[str, FlowNode],
        pool: ET.Element | None,
        process_id: str,
    ) -> dict[str, str]:
        """XML id of each task -> its actor's id; adds the actors that perform tasks."""
        lane_of: dict[str, ET.Element] = {}
        lanes = list(self._all_lanes(process))
        for lane in lanes:  # outer lanes first, so an inner lane overrides
            for reference in _children(lane, "flowNodeRef"):
                lane_of[(reference.text or "").strip()] = lane
        tasks = [node for node in nodes.values() if node.kind in TASK_KINDS]
        performers: dict[str, str] = {}
        default: str | None = None
        for task in tasks:
            if lanes:
                home = lane_of.get(task.xml_id)
                if home is None:
                    self.fail(
                        f"Task {task.xml_id} is in no lane of process {process.get('id')}; "
                        "put it in the lane of the actor who performs it.",
                        task.xml_id,
                    )
                    continue
                performers[task.xml_id] = self._actor(home, f"lane {home.get('id')}")
            elif pool is not None:
                performers[task.xml_id] = self._actor(pool, f"pool {pool.get('id')}")
            else:
                default = default or self._default_actor(process_id, process.get("name"))
                performers[task.xml_id] = default
        return performers

    def _all_lanes(self, container: ET.Element) -> Iterator[ET.Element]:
        """Every lane under the container's lane sets, outer before inner."""
        stack = list(reversed(_children(container, "laneSet")))
        while stack:
            lane_set = stack.pop()
            for lane in _children(lane_set, "lane"):
                yield lane
                stack.extend(reversed(_children(lane, "childLaneSet")))

    def _actor(self, element: ET.Element, where: str) -> str:
        """The actor a lane or pool stands for, added on first use; returns its id."""
        xml_id = element.get("id", "")
        extra = self._extra(element, where)
        actor_id = extra.get("id") if isinstance(extra.get("id"), str) else None
        actor_id = actor_id or xml_id
        if actor_id in self.actors:
            return actor_id
        name = element.get("name") or ""
        declared = _hrc(element, "actorType")
        if declared is not None and declared not in ("cobot", "operator"):
            self.fail(
                f'The {where} says hrc:actorType="{declared[:40]}"; it must be "cobot" or "operator".',
                xml_id,
            )
        actor_type = declared or ("cobot" if COBOT_NAME.search(name or xml_id) else "operator")
        actor: Json = {"id": actor_id, "type": actor_type}
        if name and name != actor_id:
            actor["name"] = name
        actor.update({k: v for k, v in extra.items() if k != "id"})
        self.actors[actor_id] = actor
        return actor_id

    def _default_actor(self, process_id: str, name: str | None) -> str:
        actor_id = self.fresh(f"{process_id}_actor")
        actor_type = "cobot" if COBOT_NAME.search(name or "") else "operator"
        self.actors[actor_id] = {"id": actor_id, "type": actor_type}
        return actor_id

    # Constraints.

    def _constraints(self, container: ET.Element) -> None:
        for association in _children(container, "association"):
            kind = _hrc(association, "constraint")
            if kind is None:
                continue  # an ordinary association (to an annotation): nothing to map
            xml_id = association.get("id", "")
            ends = [association.get(ref, "") for ref in ("sourceRef", "targetRef")]
            if not all(ends):
                self.fail(
                    f"Constraint association {xml_id} needs a sourceRef and a targetRef.", xml_id
                )
                continue
            constraint: Json = {
                "from": self.hrc_ids.get(ends[0], ends[0]),
                "to": self.hrc_ids.get(ends[1], ends[1]),
                "type": kind,
            }
            extra = self._extra(association, f"association {xml_id}")
            constraint.update({k: v for k, v in extra.items() if k != "id"})
            self.constraints.append(constraint)
