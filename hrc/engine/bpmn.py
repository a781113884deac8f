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
| start event S | a silent transition from the net's source place into its outgoing flows. The source place is S itself when the process has one start event (the step gets a fresh id), else `<process>_start` with each start event a transition S out of it (an instance starts at one of them). A process without start events starts at every node no flow enters (BPMN's implicit start) |
| end event E | a silent transition per incoming flow into the net's sink place: E itself when there is one end event, else `<process>_end`. A node no flow leaves ends its path through an extra end (BPMN's implicit end). As each end event consumes its token, the process gets `"completion": "implicit"`: a case has completed when all its tokens lie in the sink place, however many (not so in a file hrc exported, whose processes keep the pattern's rule) |
| parallel gateway G (fork, join, or both) | one silent transition G consuming all incoming and producing all outgoing flows |
| exclusive gateway G | a place where the choice or merge happens, with a silent transition per branch: a split keeps its incoming flow's place and gets a transition `G_<flow>` into each outgoing flow's place (the flow's condition becomes that transition's `guard`; the default flow's is "none of the others"); a merge gets a transition per incoming flow into the outgoing flow's place; a gateway with several of each gets its own place G between them. The branches without a condition are taken nearest an end first (fewest flows to a node no flow leaves), as the runtime takes the first branch that holds: a loop drawn with its way back first still ends |
| condition on a flow | a `guard` in hrc's language (`${a > 3}`, `#{ok && !late}`, `a gt 3` become `data.a > 3`, `data.ok and not data.late`, ... see `bpmn_conditions`); XPath over data objects (`bpmn:getDataObject('ok') = 'yes'`, `not(...)`, `true()`) too; one that does not translate (prose, XPath paths, method calls) leaves the branch without guard and with a `rewrite` key saying what to rewrite, so the model stays a draft. An empty `<conditionExpression/>` is no condition. The variables a translated condition reads become the document's `data` with a default of the type they are compared with (0, "", else false), so a case can start and its start form asks for them. Conditions (or a default flow) on the flows out of a task or event: a silent exclusive choice after it. A task that writes such a variable (a `dataOutput` of that name, or a `dataOutputAssociation` to a data object of that name) gets a `task` form asking for it (boolean, number, or a string offering the values the conditions compare it with) and an `outputs` entry storing the answer |
| event-based gateway G | a deferred choice: the events after G consume the same place, so the first to happen takes the branch |
| inclusive gateway G | where G splits into at most 4 branches that meet again at one inclusive join (a block): a silent transition per non-empty subset of branches (guarded by its conditions), each also marking a place that tells the join which subset to wait for, and a join transition per subset. A split whose branches never meet again needs no join. A join no split of its block started, or a split with more branches, is refused |
| sub-process S (and an inlined call activity) | flattened into the process between two silent steps, `S: begins` (id S) and `S: ends`: the first marks the contents' source place `S_start` and a scope place `S_scope`, the second takes the contents' sink place `S_done` and `S_scope`. Its ids keep theirs (a call activity's get `<call id>.` in front). A sub-process without contents is a task |
| call activity C | its `calledElement` names a process of the file: that process is inlined as a sub-process (and not imported on its own; a call that reaches itself again is refused); a global task, or no called element: a task (the latter with `rewrite`); else `called` finds the organisation's published pattern of that name (the calledElement, then C's name): its net is inlined between C's steps, its actors and constraints with `<C>.` in front. Unresolved: refused, naming what it calls |
| boundary event B on activity A | a silent transition consuming A's scope place (a task with boundary events gets a scope of its own: `A: begins` marks its input and the scope place, `A: ends` takes its output and the scope place). Interrupting: `cancels` every place and task inside A. Non-interrupting: an armed place marked by A's begin step lets B fire once per activation; B gives the scope place back, and A's end step `cancels` the armed place |
| message event | catching (intermediate, boundary, or start fed by a message flow): `message` named after the BPMN message, awaited with `{"case": "case.id"}`; throwing (intermediate, end): `send`. Message flows between flow nodes of the file's processes: `send` on the sender (task or event), `message` on the receiving event's transition, or on a silent step in front of a receive task (which, reached by no message flow, waits for the message it names; other tasks a message flow reaches do not wait for it, as in BPMN). Message flows to or from a pool without a process (a black box) are ignored |
| signal event | as a message named `signal:<signal name>` |
| timer event | `"timer": "<ISO duration>"` from its timeDuration; a timeDate, timeCycle or expression: `rewrite` |
| conditional event | a `guard` from its condition, else `rewrite` |
| link events | the throw event jumps to the catch event of the same name |
| error and escalation end events | thrown to the nearest enclosing activity's boundary event that catches them: the end event's transition takes that activity's scope place, `cancels` its contents (interrupting) and marks the boundary event's outgoing flows. Uncaught, an error end `cancels` the whole process and ends it; an escalation ends its path. An error or escalation boundary event nothing inside throws to waits for a message `error:<name>` (or `escalation:<name>`) |
| terminate end event | its transitions `cancels` every place and task of its scope (process or sub-process) |
| start event with a trigger | a message start no message flow feeds, a timer, signal (no signal thrown in the file), conditional, error or escalation start: a none start; the kind stays in its `bpmn` key |
| standard loop | after the task, a silent step back to its input (the loop condition as guard, else `rewrite`) and one onwards |
| multi-instance task | loopCardinality a whole number up to 20: that many copies, side by side (parallel) or one after the other (sequential), ids `T`, `T_2`, ...; else one instance with `rewrite` |
| lane | an actor (id: the lane's id), performing the tasks in it (the innermost lane when lanes nest); lanes without tasks are left out. A task inside a sub-process or called process is in its own lane, else its outermost activity's, else its pool's |
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

What the mapping does not cover is refused with a FormatError whose messages
name each element once, by kind, name and id (`task "Check order" (sid-89...)`),
at every level of the file, and say nothing of the flows that touch a refused
element: complex gateways, ad-hoc sub-processes, transactions, compensation
(compensation events, boundary events and handlers), non-interrupting event sub-processes,
unresolved call activities, inclusive gateways outside a block, choreographies
and conversations. Nothing else is read from the file, so a refused import
creates nothing. Positions (BPMNDI) are not read: `layout.lay_out` draws the
pattern in its actors' lanes.

hrc's own exports are not mapped: a process whose elements all carry the
`hrc:net` marks `bpmn_export` writes, still consistent with its `<hrc:net>`,
is rebuilt from them exactly as it was exported (ids, places, arcs, order,
layout; names, lanes and task kinds as the file now says), see `bpmn_marks`;
the collaboration's `<hrc:extra>` restores the order of actors and
constraints. A process edited in another tool so that a mark is missing or no
longer fits (a task or flow added or removed, a flow reconnected) is read by
the mapping above, and then the document keeps no layout. Through the mapping,
exclusive gateways choose when they are reached (BPMN's data-based choice),
not when a task starts: the tasks, actors, constraints and every sequence of
task starts and completions stay, but a choice between two tasks is made by a
silent step just before them.
"""

import json
import re
import xml.etree.ElementTree as ET
from collections.abc import Callable
from io import BytesIO
from typing import Any, cast

from defusedxml import (  # type: ignore[import-untyped, unused-ignore]
    DefusedXmlException,
)
from defusedxml.ElementTree import (  # type: ignore[import-untyped, unused-ignore]
    iterparse as _safe_iterparse,
)

from hrc.engine.bpmn_marks import exported_net
from hrc.engine.bpmn_net import FlowNet, Scope, describe
from hrc.engine.bpmn_scopes import FLOW_NODE_KINDS, GLOBAL_TASKS, ProcessGraph, ProcessReader
from hrc.engine.bpmn_xml import BPMN_NAMESPACE, HRC_NAMESPACE, all_lanes
from hrc.engine.bpmn_xml import bpmn_name as _bpmn
from hrc.engine.bpmn_xml import children as _children
from hrc.engine.bpmn_xml import hrc_attribute as _hrc
from hrc.engine.bpmn_xml import local_name as _local
from hrc.engine.document import FORMAT, FormatError, read_pattern
from hrc.engine.issues import Issue, error
from hrc.engine.model import Pattern
from hrc.engine.pnml import parse_xml

__all__ = [
    "BPMNDI_NAMESPACE",
    "BPMN_NAMESPACE",
    "DC_NAMESPACE",
    "DI_NAMESPACE",
    "HRC_NAMESPACE",
    "bpmn_to_document",
    "bpmn_to_pattern",
    "is_bpmn",
]

BPMNDI_NAMESPACE = "http://www.omg.org/spec/BPMN/20100524/DI"
DC_NAMESPACE = "http://www.omg.org/spec/DD/20100524/DC"
DI_NAMESPACE = "http://www.omg.org/spec/DD/20100524/DI"

Json = dict[str, Any]
Called = Callable[[list[str]], Pattern | None]
"""Finds the organisation's published pattern for a call activity, by its candidate names."""

ROOT_REFUSED = frozenset({"choreography", "globalChoreographyTask", "globalConversation"})
COLLABORATION_IGNORED = frozenset(
    {
        "documentation",
        "extensionElements",
        "participant",
        "association",
        "textAnnotation",
        "group",
        "messageFlow",
        "conversation",
        "subConversation",
        "callConversation",
        "conversationLink",
        "conversationAssociation",
        "participantAssociation",
        "messageFlowAssociation",
        "correlationKey",
    }
)
DEFINITIONS = frozenset({"message", "signal", "error", "escalation"})
COBOT_NAME = re.compile(r"cobot|robot", re.IGNORECASE)


def bpmn_to_pattern(text: str | bytes, called: Called | None = None) -> Pattern:
    """Reads a BPMN 2.0 file; raises FormatError, naming the element, when it cannot.

    `called` finds the published pattern a call activity names when no process
    of the file has that id (None: nothing is published). DTDs are refused, so
    no entity can expand or reach outside the text.
    """
    return read_pattern(bpmn_to_document(text, called))


def bpmn_to_document(text: str | bytes, called: Called | None = None) -> Json:
    """The `hrc-pattern/1` document of a BPMN file, before `read_pattern` checks its shape."""
    return _Importer(parse_xml(text, "BPMN"), called or _nothing_published).document()


def _nothing_published(names: list[str]) -> Pattern | None:
    return None


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

    def __init__(self, root: ET.Element, called: Called) -> None:
        self.root = root
        self.called = called
        self.issues: list[Issue] = []
        self.processes: dict[str, ET.Element] = {}
        self.global_tasks: dict[str, ET.Element] = {}
        self.definitions: dict[str, str] = {}
        """Id of each message, signal, error and escalation -> its name (else its id)."""
        self.received: dict[str, str] = {}
        """XML id of a flow node a message flow reaches -> the message's name."""
        self.sent: dict[str, list[str]] = {}
        self.signals_thrown: set[str] = set()
        self.elements: dict[str, ET.Element] = {}
        self.extra_reported: set[int] = set()
        self.data: dict[str, object] = {}
        """The case data the file's translated conditions read, with their defaults."""
        self.taken: set[str] = set()
        self.actors: dict[str, Json] = {}
        self.constraints: list[Json] = []
        self.hrc_ids: dict[str, str] = {}
        """XML id -> hrc id of every element that has one."""
        self.drawn_constraints: dict[str, Json] = {}
        """XML id of each constraint's association -> the constraint."""
        self.mapped = False
        """Whether some process was read through the mapping rather than from its marks."""

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
        constraint_order: list[object] = []
        for collaboration in collaborations:
            extra = self._extra(collaboration, f"collaboration {collaboration.get('id')}")
            # Our export lists the actors and constraints here, in the document's order: an
            # actor without a lane and a constraint without an association in full.
            for key, listed in (("actors", order), ("constraints", constraint_order)):
                given = extra.pop(key, [])
                listed += given if isinstance(given, list) else []
            document.update(extra)
        built = [self._process(p, participants.get(p.get("id", ""))) for p in processes]
        for container in [*processes, *collaborations]:
            self._constraints(container)
        if not self.issues and not built:
            empty = [describe("process", i, e.get("name")) for i, e in self.processes.items()]
            self.fail(
                "The file has no process with flow nodes (events, tasks, gateways) to import"
                + (
                    f": the {', the '.join(empty)} {'is' if len(empty) == 1 else 'are'} empty."
                    if empty
                    else "."
                ),
                *self.processes,
            )
        if self.issues:
            raise FormatError(list(dict.fromkeys(self.issues)))
        given = document.get("data", {})
        if self.data and isinstance(given, dict):
            document["data"] = {**self.data, **given}
        if self.mapped:
            document.pop("layout", None)  # the mapped processes' nodes have no position
        document["actors"] = self._ordered_actors(order)
        document["processes"] = built
        document["constraints"] = self._ordered_constraints(constraint_order)
        return document

    def _ordered_actors(self, order: list[object]) -> list[Json]:
        """The actors in the order the export listed them, adding those it gave in full."""
        ids: list[object] = []
        for entry in order:
            if isinstance(entry, dict) and isinstance(entry.get("id"), str):
                self.actors.setdefault(entry["id"], entry)
                ids.append(entry["id"])
            else:
                ids.append(entry)
        rank = {actor_id: index for index, actor_id in reversed(list(enumerate(ids)))}
        return sorted(self.actors.values(), key=lambda actor: rank.get(actor["id"], len(rank)))

    def _ordered_constraints(self, order: list[object]) -> list[Json]:
        """The constraints in the order the export listed them (an association's id, or the
        constraint in full), then those it did not list."""
        listed: list[Json] = []
        for entry in order:
            if isinstance(entry, dict):
                listed.append(entry)
            elif isinstance(entry, str) and entry in self.drawn_constraints:
                listed.append(self.drawn_constraints.pop(entry))
        taken = {id(constraint) for constraint in listed}
        return listed + [c for c in self.constraints if id(c) not in taken]

    # Ids.

    def _collect_ids(self) -> None:
        """Every XML id, and the hrc id its `hrc:extra` gives, so fresh ids never collide."""
        for element in self.root.iter():
            xml_id = element.get("id")
            if xml_id:
                self.elements.setdefault(xml_id, element)
                self.taken.add(xml_id)
                self.hrc_ids[xml_id] = xml_id
        for element in self.root.iter():
            xml_id = element.get("id")
            if xml_id and _bpmn(element) is not None:
                given = self._extra(element, f"element {xml_id}", report=False).get("id")
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

    def _extra(self, element: ET.Element, where: str, *, report: bool = True) -> Json:
        """The JSON object in the element's `<hrc:extra>`; {} if none or broken.

        A broken one is reported once per element, in the words of the first
        reader that reports (the ids are collected first, silently).
        """
        holder = next(iter(_children(element, "extensionElements")), None)
        if holder is None:
            return {}
        blocks = [child for child in holder if child.tag == f"{{{HRC_NAMESPACE}}}extra"]
        if not blocks:
            return {}
        xml_id = element.get("id", "")
        ids = [xml_id] if xml_id else []
        problem = None
        data: object = None
        if len(blocks) > 1:
            problem = f"The {where} has {len(blocks)} hrc:extra elements; one is allowed."
        else:
            try:
                data = cast(object, json.loads(blocks[0].text or ""))
            except (ValueError, RecursionError):
                problem = f"The hrc:extra of the {where} is not JSON."
            if problem is None and not isinstance(data, dict):
                problem = f"The hrc:extra of the {where} must be a JSON object."
        if problem is None:
            return cast(Json, data)
        if report and id(element) not in self.extra_reported:
            self.extra_reported.add(id(element))
            self.fail(problem, *ids)
        return {}

    # The file's root elements.

    def _root_elements(self) -> tuple[list[ET.Element], list[ET.Element]]:
        """The processes to import (pools, and processes no call activity inlines) and collaborations."""
        processes, collaborations = [], []
        for child in self.root:
            local = _bpmn(child) or ""
            xml_id = child.get("id", "")
            if local == "process":
                self.processes[xml_id] = child
                if any(
                    _bpmn(node) in FLOW_NODE_KINDS | {"subProcess", "callActivity"}
                    for node in child
                ):
                    processes.append(child)
            elif local == "collaboration":
                collaborations.append(child)
            elif local in GLOBAL_TASKS:
                self.global_tasks[xml_id] = child
            elif local in DEFINITIONS:
                self.definitions[xml_id] = (child.get("name") or "").strip() or xml_id
            elif local in ROOT_REFUSED or local.startswith(("choreography", "conversation")):
                what = describe(local, xml_id, child.get("name"))
                self.fail(
                    f"The {what} cannot be imported: hrc imports processes, pools and lanes.",
                    *([xml_id] if xml_id else []),
                )
        called = {
            element.get("calledElement", "")
            for process in processes
            for element in process.iter(f"{{{BPMN_NAMESPACE}}}callActivity")
        }
        return [p for p in processes if p.get("id") not in called], collaborations

    def _participants(self, collaborations: list[ET.Element]) -> dict[str, ET.Element]:
        """Process id -> its participant (pool); reads message flows; refuses the rest."""
        participants: dict[str, ET.Element] = {}
        for collaboration in collaborations:
            for child in collaboration:
                local = _bpmn(child)
                if local == "participant" and child.get("processRef"):
                    participants.setdefault(child.get("processRef", ""), child)
                elif local == "messageFlow":
                    self._message_flow(child)
                elif local is not None and local not in COLLABORATION_IGNORED:
                    self._refuse_element(child, local)
        for process in self.processes.values():
            for element in process.iter():
                if _bpmn(element) == "signalEventDefinition" and element.get("signalRef"):
                    name = self.definitions.get(element.get("signalRef", ""), "")
                    self.signals_thrown.add(f"signal:{name}")
        return participants

    def _message_flow(self, flow: ET.Element) -> None:
        """A message between two flow nodes of the file's processes; pools as ends are ignored.

        Its name is the BPMN message's it (or its sender) refers to, else its own
        name, else its id.
        """
        source, target = flow.get("sourceRef", ""), flow.get("targetRef", "")
        named = [
            self.definitions.get(flow.get("messageRef", "")),
            *self._event_message(source),
            *self._event_message(target),
            (flow.get("name") or "").strip() or None,
            flow.get("id", ""),
        ]
        # Every flow into one receiver carries the name it awaits.
        name = self.received.get(target) or next(n for n in named if n is not None)
        self.sent.setdefault(source, []).append(name)
        self.received.setdefault(target, name)

    def _event_message(self, xml_id: str) -> list[str | None]:
        """The name of the message an event or task refers to, if any."""
        element = self.elements.get(xml_id)
        if element is None:
            return []
        references = [element.get("messageRef")] + [
            d.get("messageRef") for d in _children(element, "messageEventDefinition")
        ]
        return [self.definitions.get(r or "") for r in references if r]

    def _refuse_element(self, element: ET.Element, local: str) -> None:
        xml_id = element.get("id", "")
        what = describe(local, xml_id or "(without id)", element.get("name"))
        self.fail(
            f"The {what} cannot be imported: hrc does not map <{local}> here.",
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
        exported = exported_net(element, self)
        if exported is not None:
            return exported
        self.mapped = True
        process_xml_id = element.get("id", "")
        if not process_xml_id:
            self.fail("A <process> has no id; BPMN needs one on every process.")
        process_id = self.hrc_id(process_xml_id)
        graph = ProcessReader(self, element, process_id, self.called).read()
        net = FlowNet(self.fresh, process_id, graph.flows)
        self._scope_places(graph, net)
        performers = self._lanes(element, graph, pool, process_id)
        for node in graph.nodes:
            net.add(node, performers.get(node.hrc_id))
        for scope, call_id, pattern in graph.inlined:
            performers.update(self._inline(net, scope, call_id, pattern))
        for scope_id, scope in graph.scopes.items():
            net.ends(graph.starts.get(scope_id, []), scope, start=True)
            net.ends(graph.ends.get(scope_id, []), scope, start=False)
        net.finish()
        _mark_the_start(net)
        for key, value in graph.data.items():
            self.data.setdefault(key, value)
        data: Json = {"id": process_id, "workpiece": _workpiece(element, pool, process_id)}
        data["actors"] = list(dict.fromkeys(performers.values()))
        if element.get("name"):
            data["name"] = element.get("name")
        if self.root.get("exporter") != "hrc":
            # BPMN's own rule; a file hrc wrote keeps the pattern's, in its hrc:extra if any.
            data["completion"] = "implicit"
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

    def _scope_places(self, graph: ProcessGraph, net: FlowNet) -> None:
        """Every scope's source, sink, scope and armed places.

        The process' source and sink are named after its start or end event when
        it has one (as BPMN export writes them); its scope place belongs to the
        enclosing scope, so what cancels inside a scope never empties it.
        """
        root = graph.root
        for kind, events in (("start", graph.starts), ("end", graph.ends)):
            found = events.get(root.hrc_id, [])
            if len(found) == 1:
                event = found[0]
                named = {"name": event.name} if event.name else {}
                extra = {k: v for k, v in event.extra.items() if k != "id"}
                place = net.place(event.hrc_id, root, **named, **extra)
            else:
                place = net.place(self.fresh(f"{root.hrc_id}_{kind}"), root)
            if kind == "start":
                root.source = place
            else:
                root.sink = place
            if not found:
                what = describe("process", root.hrc_id, None)
                self.fail(f"The {what} has no flow nodes to {kind} at.", root.hrc_id)
        if root.place is not None:
            net.place(root.place, root)
        for scope in graph.scopes.values():
            if scope is root:
                continue
            for place in (scope.source, scope.sink, *scope.armed):
                net.place(place, scope)
            net.place(scope.place or "", scope.parent or root)

    def _inline(self, net: FlowNet, scope: Scope, call_id: str, pattern: Pattern) -> dict[str, str]:
        """Copies a called pattern's net into the call activity's scope; returns task -> actor.

        Its source and sink places become the scope's; every other id and its
        actors get the call activity's id in front, and its constraints come along.
        """
        process = pattern.processes[0]
        ids: dict[str, str] = {}
        ids.update(dict.fromkeys(process.source_places()[:1], scope.source))
        ids.update(dict.fromkeys(process.sink_places()[:1], scope.sink))
        for element_id in [p.id for p in process.places] + [t.id for t in process.transitions]:
            ids.setdefault(element_id, self.fresh(f"{call_id}.{element_id}"))
        actors: dict[str, str] = {}
        for actor in pattern.actors:
            actors[actor.id] = self.fresh(f"{call_id}.{actor.id}")
            self.actors[actors[actor.id]] = {
                "id": actors[actor.id],
                "type": actor.type,
                **actor.extra,
            }
        for place in process.places:
            net.place(ids[place.id], scope, **place.extra)
        performers: dict[str, str] = {}
        for transition in process.transitions:
            performer = actors.get(transition.performer or "")
            net.transition(
                ids[transition.id],
                scope,
                performer=performer,
                label=transition.label,
                extra=dict(transition.extra),
            )
            if performer is not None:
                performers[ids[transition.id]] = performer
        for source, target in process.arcs:
            net.arc(ids[source], ids[target])
        for constraint in pattern.constraints:
            if constraint.source in ids and constraint.target in ids:
                self.constraints.append(
                    {
                        "from": ids[constraint.source],
                        "to": ids[constraint.target],
                        "type": constraint.type,
                        **constraint.extra,
                    }
                )
        return performers

    # What the process reader asks.

    def hrc_id(self, xml_id: str) -> str:
        return self.hrc_ids.get(xml_id, xml_id)

    def extra(self, element: ET.Element, where: str) -> Json:
        return self._extra(element, where)

    def process_element(self, xml_id: str) -> ET.Element | None:
        return self.processes.get(xml_id)

    def global_task(self, xml_id: str) -> ET.Element | None:
        return self.global_tasks.get(xml_id)

    def definition_name(self, reference: str | None) -> str | None:
        return self.definitions.get(reference or "")

    def message_in(self, xml_id: str) -> str | None:
        return self.received.get(xml_id)

    def messages_out(self, xml_id: str) -> list[str]:
        return self.sent.get(xml_id, [])

    def signal_thrown(self, name: str) -> bool:
        return name in self.signals_thrown

    def performer(self, lane: ET.Element) -> str:
        """The actor a lane declares with hrc:actorType, else the performer id it stands for."""
        if _hrc(lane, "actorType") is not None:
            return self._actor(lane, f"lane {lane.get('id')}")
        return self.hrc_id(lane.get("id", ""))

    def event_definition(self, xml_id: str) -> ET.Element | None:
        element = self.elements.get(xml_id)
        local = _bpmn(element) if element is not None else None
        return element if local and local.endswith("EventDefinition") else None

    # Lanes and actors.

    def _lanes(
        self,
        process: ET.Element,
        graph: ProcessGraph,
        pool: ET.Element | None,
        process_id: str,
    ) -> dict[str, str]:
        """hrc id of each task -> its actor's id; adds the actors that perform tasks.

        A task inside a sub-process or called process is in the lane of its
        outermost activity, unless its own lanes say otherwise; a task in no
        lane is the pool's.
        """
        lane_of: dict[str, ET.Element] = {}
        # A called process' own lanes count for the tasks inlined from it.
        lanes = list(all_lanes(process)) + [
            lane
            for other in self.processes.values()
            if other is not process
            for lane in all_lanes(other)
        ]
        for lane in lanes:  # outer lanes first, so an inner lane overrides
            for reference in _children(lane, "flowNodeRef"):
                lane_of[(reference.text or "").strip()] = lane
        performers: dict[str, str] = {}
        default: str | None = None
        for task_id, lookups in graph.tasks.items():
            home = next((lane_of[i] for i in lookups if i in lane_of), None)
            if home is not None:
                performers[task_id] = self._actor(home, f"lane {home.get('id')}")
            elif pool is not None:
                performers[task_id] = self._actor(pool, f"pool {pool.get('id')}")
            else:
                default = default or self._default_actor(process_id, process.get("name"))
                performers[task_id] = default
        return performers

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
            self.drawn_constraints[xml_id] = constraint


def _mark_the_start(net: FlowNet) -> None:
    """Writes the start's token once a place no token reaches says it holds none: the default
    marking (a token in every place no arrow enters) would start the case there too."""
    if not any(place.get("tokens") == 0 for place in net.places):
        return
    entered = {target for _, target in net.arcs}
    for place in net.places:
        if place["id"] not in entered and "tokens" not in place:
            place["tokens"] = 1
