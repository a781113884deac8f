"""hrc's own BPMN exports read back exactly: the marks `bpmn_export` leaves and how they are checked.

The export draws a net as BPMN (`bpmn_export`'s table), and BPMN's mapping
(`bpmn.py`) would read that drawing back as another net with the same
behaviour: every sequence flow a place, every event and gateway a silent step.
So the export says, on each element it writes, what that element stands for,
and keeps the net's order in the process:

| mark (`hrc:net`) | on | stands for |
| --- | --- | --- |
| `transition <id>` | a task, a parallel gateway, an intermediate event | the transition; `<id>` is the element's own |
| `join <id>` | a parallel gateway | the input of transition `<id>` (a task or event with several input places) |
| `place <id>` | a start or end event, a sequence flow, an exclusive or event-based gateway | the place; `<id>` is the element's own |
| `split <id>` | an exclusive or event-based gateway | the choice of place `<id>` between its output transitions |
| `merge <id>` | an exclusive gateway | the merge of the transitions that mark place `<id>` (a flow) |
| `arc` | a sequence flow | the arcs between the nodes its two ends stand for |

Ids in marks are XML ids. The process' `<extensionElements>` hold `<hrc:net>`,
a JSON object: the process' `actors`, the ids of its `places` and
`transitions` and its `arcs`, in the document's order, and the `layout` of
each node that had one.

`exported_net` rebuilds a process from them when the file still holds exactly
what was exported: every flow node and sequence flow marked, each mark on the
kind of element the export writes for it, nothing added inside the elements
but documentation, and the marks giving back the same places, transitions and
arcs as `<hrc:net>` lists. Names, lanes (performers), task kinds and
`<hrc:extra>` are read from the elements, so a task renamed, moved to another
lane or made a user task in another tool comes back so. Anything else (a task
or flow added, removed or reconnected, a loop or a boundary event added, a
gateway changed) leaves a mark missing or the net different, and the process
is read by the mapping instead.
"""

import json
import xml.etree.ElementTree as ET
from collections import Counter
from typing import Any, Protocol, cast

from hrc.engine.bpmn_net import TASK_KINDS
from hrc.engine.bpmn_xml import HRC_NAMESPACE, all_lanes, bpmn_name, children, hrc_attribute

Json = dict[str, Any]

MARK = "net"
"""The attribute on each element (`hrc:net`) and the process' extension element (`<hrc:net>`)."""
TRANSITION, JOIN, PLACE, SPLIT, MERGE, ARC = "transition", "join", "place", "split", "merge", "arc"
MARKED_KINDS = {
    TRANSITION: TASK_KINDS
    | {"parallelGateway", "intermediateCatchEvent", "intermediateThrowEvent"},
    JOIN: frozenset({"parallelGateway"}),
    PLACE: frozenset({"startEvent", "endEvent", "exclusiveGateway", "eventBasedGateway"}),
    SPLIT: frozenset({"exclusiveGateway", "eventBasedGateway"}),
    MERGE: frozenset({"exclusiveGateway"}),
}
EVENT_DEFINITIONS = frozenset({"timerEventDefinition", "messageEventDefinition"})
INSIDE = frozenset({"extensionElements", "documentation", "incoming", "outgoing"})
"""What an exported element may hold besides an intermediate event's definition."""
UNMARKED = frozenset(
    {
        "documentation",
        "extensionElements",
        "laneSet",
        "association",
        "textAnnotation",
        "group",
        "dataObject",
        "dataObjectReference",
        "dataStoreReference",
    }
)
"""Children of a process that carry no control flow, so need no mark."""


def mark(role: str, xml_id: str | None = None) -> str:
    return role if xml_id is None else f"{role} {xml_id}"


class MarkReading(Protocol):
    """What the file's reader gives `exported_net`."""

    def hrc_id(self, xml_id: str) -> str: ...

    def extra(self, element: ET.Element, where: str) -> Json: ...

    def performer(self, lane: ET.Element) -> str:
        """The actor (or undeclared performer) a lane stands for; registers a declared actor."""
        ...


def exported_net(process: ET.Element, reading: MarkReading) -> Json | None:
    """The process' `hrc-pattern/1` object as hrc exported it; None when the file no longer says it.

    Reads the lanes of the process (registering their actors) only when it returns one.
    """
    record = _record(process)
    if record is None:
        return None
    marked = _Marked(process, reading)
    if not marked.read() or not marked.holds(record):
        return None
    lanes = marked.lanes()
    if lanes is None:
        return None
    # Every lane, so that each declared actor comes back, performing tasks or not.
    registered = {id(lane): reading.performer(lane) for lane in all_lanes(process)}
    performers = {xml_id: registered[id(lane)] for xml_id, lane in lanes.items()}
    data: Json = {"id": reading.hrc_id(process.get("id", ""))}
    workpiece = hrc_attribute(process, "workpiece")
    if workpiece is not None:
        data["workpiece"] = workpiece
    data["actors"] = record["actors"]
    if process.get("name") is not None:
        data["name"] = process.get("name")
    data.update(_own(reading, process))
    layout = record["layout"]
    data["places"] = [
        _node(reading, marked.places[place_id], layout, place_id) for place_id in record["places"]
    ]
    data["transitions"] = [
        _transition(reading, marked.transitions[transition_id], layout, transition_id, performers)
        for transition_id in record["transitions"]
    ]
    data["arcs"] = record["arcs"]
    return data


def _record(process: ET.Element) -> Json | None:
    """The process' `<hrc:net>` when it has one of the right shape."""
    holder = next(iter(children(process, "extensionElements")), None)
    found = [] if holder is None else [c for c in holder if c.tag == f"{{{HRC_NAMESPACE}}}{MARK}"]
    if len(found) != 1:
        return None
    try:
        record = cast(object, json.loads(found[0].text or ""))
    except (ValueError, RecursionError):
        return None
    if not isinstance(record, dict):
        return None
    ids = [record.get(key) for key in ("actors", "places", "transitions")]
    arcs = record.get("arcs")
    if not (
        all(isinstance(i, list) and all(isinstance(x, str) for x in i) for i in ids)
        and isinstance(arcs, list)
        and all(
            isinstance(a, list) and len(a) == 2 and all(isinstance(x, str) for x in a) for a in arcs
        )
        and isinstance(record.get("layout"), dict)
    ):
        return None
    return cast(Json, record)


def _own(reading: MarkReading, element: ET.Element) -> Json:
    """The element's `<hrc:extra>` but its id, which `hrc_id` already gave."""
    where = f"element {element.get('id', '')}"
    return {k: v for k, v in reading.extra(element, where).items() if k != "id"}


def _node(reading: MarkReading, element: ET.Element, layout: Json, node_id: str) -> Json:
    data: Json = {"id": node_id}
    if element.get("name") is not None:
        data["name"] = element.get("name")
    data.update(_own(reading, element))
    if node_id in layout:
        data["layout"] = layout[node_id]
    return data


def _transition(
    reading: MarkReading,
    element: ET.Element,
    layout: Json,
    transition_id: str,
    performers: dict[str, str],
) -> Json:
    data: Json = {"id": transition_id}
    kind = bpmn_name(element) or ""
    if kind in TASK_KINDS:
        data["performer"] = performers[element.get("id", "")]
        if kind != "task":
            data["bpmn"] = kind
    if element.get("name") is not None:
        data["label"] = element.get("name")
    data.update(_own(reading, element))
    if transition_id in layout:
        data["layout"] = layout[transition_id]
    return data


class _Marked:
    """A process' marked elements, and the net their marks and flows give."""

    def __init__(self, process: ET.Element, reading: MarkReading) -> None:
        self.process = process
        self.reading = reading
        self.nodes: dict[str, tuple[str, str, ET.Element]] = {}
        """XML id of each flow node -> (role, XML id of what it stands for, element)."""
        self.flows: list[tuple[str, ET.Element]] = []
        """(role, element) of each sequence flow."""
        self.place_flows: set[str] = set()
        """XML ids of the sequence flows that stand for a place."""
        self.places: dict[str, ET.Element] = {}
        self.transitions: dict[str, ET.Element] = {}
        """hrc id -> the element standing for it."""
        self.place_list: list[str] = []
        self.transition_list: list[str] = []

    def read(self) -> bool:
        """Whether every flow node and sequence flow carries a mark that fits its element."""
        for child in self.process:
            local = bpmn_name(child)
            if local is None or local in UNMARKED:
                continue
            found = _mark_of(child)
            if found is None:
                return False
            role, owner = found
            xml_id = child.get("id", "")
            if local == "sequenceFlow":
                if not self._fits_flow(child, role, owner):
                    return False
                self.flows.append((role, child))
                if role == PLACE:
                    self.place_flows.add(xml_id)
                    self._add(self.places, self.place_list, child)
            elif owner is not None and self._fits_node(child, local, role, owner):
                self.nodes[xml_id] = (role, owner, child)
                if role == PLACE:
                    self._add(self.places, self.place_list, child)
                elif role == TRANSITION:
                    self._add(self.transitions, self.transition_list, child)
            else:
                return False
        return True

    def _add(self, found: dict[str, ET.Element], order: list[str], element: ET.Element) -> None:
        hrc_id = self.reading.hrc_id(element.get("id", ""))
        found.setdefault(hrc_id, element)
        order.append(hrc_id)

    def _fits_flow(self, flow: ET.Element, role: str, owner: str | None) -> bool:
        inside = {bpmn_name(c) for c in flow} <= {"extensionElements", "documentation"}
        own = owner == flow.get("id") if role == PLACE else owner is None and role == ARC
        return inside and own

    def _fits_node(self, element: ET.Element, local: str, role: str, owner: str) -> bool:
        if local not in MARKED_KINDS.get(role, ()):
            return False
        if role in (TRANSITION, PLACE) and owner != element.get("id"):
            return False
        allowed = INSIDE | (EVENT_DEFINITIONS if local.startswith("intermediate") else set())
        return {bpmn_name(c) for c in element} <= allowed

    def holds(self, record: Json) -> bool:
        """Whether the marks give back the places, transitions and arcs `record` lists."""
        arcs = self._arcs()
        return (
            arcs is not None
            and sorted(self.place_list) == sorted(record["places"])
            and sorted(self.transition_list) == sorted(record["transitions"])
            and Counter(arcs) == Counter(tuple(arc) for arc in record["arcs"])
        )

    def _stands_for(self, xml_id: str) -> tuple[str, str] | None:
        """(role, hrc id) of the net node a flow node's element stands for."""
        if xml_id not in self.nodes:
            return None
        role, owner, _ = self.nodes[xml_id]
        if role == JOIN:
            ok = self.nodes.get(owner, ("",))[0] == TRANSITION
        elif role == SPLIT:
            ok = self.nodes.get(owner, ("",))[0] == PLACE or owner in self.place_flows
        elif role == MERGE:
            ok = owner in self.place_flows
        else:
            ok = True
        return (role, self.reading.hrc_id(owner)) if ok else None

    def _arcs(self) -> list[tuple[str, str]] | None:
        arcs: list[tuple[str, str]] = []
        for role, flow in self.flows:
            source = self._stands_for(flow.get("sourceRef", ""))
            target = self._stands_for(flow.get("targetRef", ""))
            if source is None or target is None:
                return None
            (source_role, a), (target_role, b) = source, target
            if role == PLACE:
                place = self.reading.hrc_id(flow.get("id", ""))
                arcs += [(a, place)] if a != place else []
                arcs += [(place, b)] if b != place else []
            elif a != b:
                arcs.append((a, b))
            elif (source_role, target_role) not in ((JOIN, TRANSITION), (PLACE, SPLIT)):
                return None
        return arcs

    def lanes(self) -> dict[str, ET.Element] | None:
        """XML id of each task -> its lane (the innermost); None when a task is in none."""
        lane_of: dict[str, ET.Element] = {}
        for lane in all_lanes(self.process):
            for reference in children(lane, "flowNodeRef"):
                lane_of[(reference.text or "").strip()] = lane
        tasks = [e.get("id", "") for e in self.transitions.values() if bpmn_name(e) in TASK_KINDS]
        if any(task not in lane_of for task in tasks):
            return None
        return {task: lane_of[task] for task in tasks}


def _mark_of(element: ET.Element) -> tuple[str, str | None] | None:
    """(role, XML id) of an element's mark; None when it has none that reads."""
    words = (hrc_attribute(element, MARK) or "").split()
    if len(words) == 1 and words[0] == ARC:
        return ARC, None
    if len(words) == 2 and words[0] in MARKED_KINDS:
        return words[0], words[1]
    return None
