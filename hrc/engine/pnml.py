"""PNML (ISO/IEC 15909-2) import and export of collaboration patterns, P/T nets only.

`pattern_to_pnml` writes one `<net>` per pattern and one `<page>` per process
(a coexistence pattern has several). The net is plain PNML that any P/T tool
reads: places with names and initial markings, transitions with labels, arcs.
What PNML cannot say travels as JSON in `<toolspecific tool="hrc" version="1">`
on the element it belongs to: actors, performers, constraints, workpieces,
every element's unknown keys, and any id or text that XML cannot hold as
written. Each block holds exactly the keys of the element's `hrc-pattern/1`
object that the standard part does not carry faithfully, and overrides the
standard part on import, so our own files come back exactly.

`pnml_to_pattern` reads those files, and PNML from other tools (pm4py, WoPeD,
PIPE, ...) as one process per `<net>`, without actors (a draft the engineer
gives lanes: `no-actors`), working on a workpiece named after the net's name
or id (wpassign is total). Both ways build an
`hrc-pattern/1` document and hand it to `read_pattern`, so a PNML file passes
the same shape checks as a JSON one and fails with the same `FormatError`.
Arcs are kept as written: an arc to a node that does not exist is the rules'
`unknown-node`, as in a JSON document.

PIPE writes its own dialect: the net type `P/T net`, names and numbers in
`<value>` rather than `<text>`, and a number per token colour
(`Default,1`). A net of one colour reads as a P/T net; PIPE's timing (GSPN
rates, immediate or timed transitions, priorities) is dropped, as hrc's
analysis abstracts time away. What would change the net's behaviour is
refused by element: a second token colour, an inhibitor arc, a place's
capacity. A foreign net without an id (PIPE 5 writes none) is named `net`.

Places have no label in `hrc-pattern/1`: a place's PNML name is the `name` in
its extras where it has one, else its id, and a foreign place whose name
differs from its id keeps it there. Editor positions `x`, `y` in the extras
are also written as standard graphics, and foreign graphics are read into them.
"""

import json
import math
import re
import xml.etree.ElementTree as ET
from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import Any, Literal, cast

# defusedxml ships no type stubs; the names used here are re-typed by the casts and
# `except` clauses below. `unused-ignore` keeps this quiet where mypy is told to
# ignore missing imports anyway (our pyproject does).
from defusedxml import (  # type: ignore[import-untyped, unused-ignore]
    DefusedXmlException,
    DTDForbidden,
    EntitiesForbidden,
    ExternalReferenceForbidden,
)
from defusedxml.ElementTree import (  # type: ignore[import-untyped, unused-ignore]
    fromstring as _safe_fromstring,
)

from hrc.engine.document import FORMAT, FormatError, read_pattern, write_pattern
from hrc.engine.issues import Issue, error
from hrc.engine.model import Pattern
from hrc.engine.wording import sentence

PNML_NAMESPACE = "http://www.pnml.org/version-2009/grammar/pnml"
PTNET_TYPE = "http://www.pnml.org/version-2009/grammar/ptnet"
CORE_MODEL_TYPE = "http://www.pnml.org/version-2009/grammar/pnmlcoremodel"
"""The type pm4py and ProM write for their P/T nets; read like PTNET_TYPE."""
PIPE_NET_TYPE = "P/T net"
"""The type PIPE writes on its nets, coloured or not."""
NET_TYPES = (PTNET_TYPE, CORE_MODEL_TYPE, PIPE_NET_TYPE)
TOOL = "hrc"
TOOL_VERSION = "1"

Json = dict[str, Any]
NodeKind = Literal["place", "transition"]


def pattern_to_pnml(pattern: Pattern) -> str:
    """The PNML document of a pattern; `pnml_to_pattern` reads it back equal, extras included.

    The extras must be JSON values, as for `document.dumps`.
    """
    document = write_pattern(pattern)
    ids = _XmlIds(document)
    root = ET.Element("pnml", xmlns=PNML_NAMESPACE)
    root.append(_write_net(document, ids))
    ET.indent(root)
    return '<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(root, encoding="unicode") + "\n"


def pnml_to_pattern(text: str | bytes) -> Pattern:
    """Reads a PNML document; raises FormatError, never another error, when it cannot.

    Files written by `pattern_to_pnml` come back with actors, performers and
    constraints; PNML from other tools becomes one process per `<net>` with no
    actors. DTDs are refused, so no entity can expand or reach outside the text.
    """
    return read_pattern(_Reader(parse_xml(text, "PNML")).document())


# Writing ---------------------------------------------------------------------------------


class _XmlIds:
    """PNML ids for a document's pages, places and transitions, and generated ones for the rest.

    PNML ids are XML ids: NCNames, unique in the file. An element keeps its hrc id
    where that is one and is not taken yet (duplicate ids are the rules' business,
    so they must survive a round trip); otherwise it gets a generated id and its
    hrc id travels in its toolspecific.
    """

    def __init__(self, document: Json) -> None:
        processes: list[Json] = document["processes"]
        self._reserved = {
            element["id"]
            for process in processes
            for element in [process, *process["places"], *process["transitions"]]
            if _is_ncname(element["id"])
        }
        self._taken: set[str] = set()
        self._counters: dict[str, int] = {}
        self.pages = [self._assign(process["id"], "page") for process in processes]
        self.places = [[self._assign(p["id"], "p") for p in pr["places"]] for pr in processes]
        self.transitions = [
            [self._assign(t["id"], "t") for t in pr["transitions"]] for pr in processes
        ]
        self.node: dict[str, str] = {}
        """hrc node id -> the PNML id of the first place or transition that has it."""
        self.back: dict[str, str] = {}
        """PNML id -> hrc id, as the reader maps an arc's end."""
        for process, places, transitions in zip(
            processes, self.places, self.transitions, strict=True
        ):
            for element, xml_id in zip(
                process["places"] + process["transitions"], places + transitions, strict=True
            ):
                self.node.setdefault(element["id"], xml_id)
                self.back[xml_id] = element["id"]

    def _assign(self, hrc_id: str, prefix: str) -> str:
        if _is_ncname(hrc_id) and hrc_id not in self._taken:
            self._taken.add(hrc_id)
            return hrc_id
        return self.fresh(prefix)

    def fresh(self, prefix: str) -> str:
        """A new id that is no element's hrc id, so it cannot steal one that comes later."""
        while True:
            self._counters[prefix] = self._counters.get(prefix, 0) + 1
            candidate = f"{prefix}{self._counters[prefix]}"
            if candidate not in self._reserved and candidate not in self._taken:
                self._taken.add(candidate)
                return candidate


def _write_net(document: Json, ids: _XmlIds) -> ET.Element:
    net = ET.Element("net", id=ids.fresh("net"), type=PTNET_TYPE)
    tool = {key: value for key, value in document.items() if key != "processes"}
    if _is_text(document["name"]):
        _add_text(net, "name", document["name"])
        del tool["name"]
    _add_tool(net, tool)
    for index, process in enumerate(document["processes"]):
        net.append(_write_page(process, index, ids))
    return net


def _write_page(process: Json, index: int, ids: _XmlIds) -> ET.Element:
    page = ET.Element("page", id=ids.pages[index])
    tool = {k: v for k, v in process.items() if k not in ("places", "transitions", "arcs")}
    _add_tool(page, _without_faithful_id(tool, ids.pages[index]))
    for place, xml_id in zip(process["places"], ids.places[index], strict=True):
        page.append(_write_place(place, xml_id))
    for transition, xml_id in zip(process["transitions"], ids.transitions[index], strict=True):
        page.append(_write_transition(transition, xml_id))
    for source, target in process["arcs"]:
        page.append(_write_arc(source, target, ids))
    return page


def _write_place(place: Json, xml_id: str) -> ET.Element:
    element = ET.Element("place", id=xml_id)
    tool = _without_faithful_id(place, xml_id)
    # Places have no label in hrc-pattern/1; other tools show the name, so give them one.
    name = place.get("name")
    if not (isinstance(name, str) and _is_text(name)):
        name = place["id"] if _is_text(place["id"]) else xml_id
    _add_text(element, "name", name)
    _add_position(element, place)
    tokens = place.get("tokens")
    if isinstance(tokens, int) and not isinstance(tokens, bool) and tokens >= 0:
        _add_text(element, "initialMarking", str(tokens))
        del tool["tokens"]
    _add_tool(element, tool)
    return element


def _write_transition(transition: Json, xml_id: str) -> ET.Element:
    element = ET.Element("transition", id=xml_id)
    tool = _without_faithful_id(transition, xml_id)
    label = transition.get("label")
    if isinstance(label, str) and _is_text(label):
        _add_text(element, "name", label)
        del tool["label"]
    _add_position(element, transition)
    if label is None and transition.get("performer") is None:
        # A silent routing step: pm4py and ProM read this as an invisible (τ) transition.
        ET.SubElement(element, "toolspecific", tool="ProM", version="6.4", activity="$invisible$")
    _add_tool(element, tool)
    return element


def _write_arc(source: str, target: str, ids: _XmlIds) -> ET.Element:
    ends = {"from": source, "to": target}
    written = {key: ids.node.get(end) or _attribute_safe(end) for key, end in ends.items()}
    element = ET.Element("arc", id=ids.fresh("a"), source=written["from"], target=written["to"])
    # An end the reader would map to another id (a dangling id that is also a generated
    # one, an id XML cannot hold) is written out in full.
    _add_tool(
        element, {k: end for k, end in ends.items() if ids.back.get(written[k], written[k]) != end}
    )
    return element


def _without_faithful_id(data: Json, xml_id: str) -> Json:
    return {key: value for key, value in data.items() if key != "id" or value != xml_id}


def _add_text(parent: ET.Element, tag: str, text: str) -> None:
    ET.SubElement(ET.SubElement(parent, tag), "text").text = text


def _add_tool(parent: ET.Element, data: Json) -> None:
    if data:
        block = ET.SubElement(parent, "toolspecific", tool=TOOL, version=TOOL_VERSION)
        block.text = _json_text(data)


def _add_position(parent: ET.Element, data: Json) -> None:
    """Standard graphics from an editor position in the extras; the toolspecific stays the truth."""
    x, y = data.get("x"), data.get("y")
    if _is_coordinate(x) and _is_coordinate(y):
        graphics = ET.SubElement(parent, "graphics")
        ET.SubElement(graphics, "position", x=repr(x), y=repr(y))


def _is_coordinate(value: object) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value)


def _json_text(data: Json) -> str:
    # JSON escapes control characters itself; lone surrogates and U+FFFE/U+FFFF are the
    # characters left that XML cannot hold, and they can only occur inside JSON strings.
    text = json.dumps(data, ensure_ascii=False)
    return _NOT_IN_XML_EXCEPT_CONTROL.sub(lambda m: f"\\u{ord(m.group()):04x}", text)


# XML 1.0 Char, and the NCName an XML id must be (Namespaces in XML 1.0, 3rd ed.).
_NOT_XML_CHAR = re.compile("[^\t\n\r\x20-\ud7ff\ue000-\ufffd\U00010000-\U0010ffff]")
_NOT_IN_XML_EXCEPT_CONTROL = re.compile("[\ud800-\udfff\ufffe\uffff]")
_NAME_START = (
    "A-Z_a-z\xc0-\xd6\xd8-\xf6\xf8-\u02ff\u0370-\u037d\u037f-\u1fff\u200c-\u200d"
    "\u2070-\u218f\u2c00-\u2fef\u3001-\ud7ff\uf900-\ufdcf\ufdf0-\ufffd\U00010000-\U000effff"
)
_NCNAME = re.compile(f"[{_NAME_START}][{_NAME_START}\\-.0-9\xb7\u0300-\u036f\u203f-\u2040]*")


def _is_ncname(value: str) -> bool:
    return _NCNAME.fullmatch(value) is not None


def _is_text(value: str) -> bool:
    """Whether XML character data gives back exactly this string (parsers turn CR into LF)."""
    return "\r" not in value and _NOT_XML_CHAR.search(value) is None


def _attribute_safe(value: str) -> str:
    # ElementTree escapes CR, LF and tab in attributes, so only non-characters need replacing.
    return _NOT_XML_CHAR.sub("\ufffd", value)


# Reading ---------------------------------------------------------------------------------


def _refuse(message: str) -> FormatError:
    return FormatError([error("format", message)])


def parse_xml(text: str | bytes, what: str) -> ET.Element:
    """A parsed XML tree of a `what` file (PNML, BPMN); FormatError for malformed or unsafe XML
    (DTDs, entities, external references), with the parser's line and column."""
    try:
        return cast(
            ET.Element,
            _safe_fromstring(text, forbid_dtd=True, forbid_entities=True, forbid_external=True),
        )
    except DTDForbidden:
        raise _refuse(
            f"The document has a DTD (<!DOCTYPE ...>), which is refused: {what} needs none, and a"
            " DTD can define entities that expand without limit (an XML bomb) or read other files"
            " (external entities)."
        ) from None
    except EntitiesForbidden as exc:
        raise _refuse(f"The document declares the entity {exc.name!r}, which is refused.") from None
    except ExternalReferenceForbidden:
        raise _refuse("The document refers to an external resource, which is refused.") from None
    except DefusedXmlException as exc:
        raise _refuse(f"The document was refused as unsafe XML: {exc}.") from None
    except ET.ParseError as exc:
        raise _refuse(f"The document is not XML: {exc}.") from None
    except UnicodeError:
        raise _refuse("The document is not valid Unicode text.") from None
    except LookupError as exc:  # an encoding declaration Python does not know
        raise _refuse(f"The document is in an unknown encoding: {exc}.") from None


@dataclass
class _Node:
    element: ET.Element
    kind: NodeKind
    xml_id: str
    tool: Json | None
    """The hrc toolspecific, read only in our own files."""

    @property
    def hrc_id(self) -> str:
        written = (self.tool or {}).get("id")
        return written if isinstance(written, str) and written else self.xml_id


@dataclass
class _Contents:
    """The objects of a net or page, nested pages flattened, in document order."""

    nodes: list[_Node] = field(default_factory=list)
    arcs: list[ET.Element] = field(default_factory=list)
    references: list[ET.Element] = field(default_factory=list)


_REFERENCE_KINDS: dict[str, NodeKind] = {
    "referencePlace": "place",
    "referenceTransition": "transition",
}


class _Reader:
    """Turns a PNML tree into an `hrc-pattern/1` document, collecting every structural problem."""

    def __init__(self, root: ET.Element) -> None:
        self.root = root
        self.ns = ""
        self.issues: list[Issue] = []
        self.labels: dict[str, str] = {}
        """Every named element's name by id, for messages."""

    def fail(self, message: str, *elements: str) -> None:
        self.issues.append(error("format", message, *elements))

    def document(self) -> Json:
        """Raises FormatError when the tree is not a PNML P/T net document."""
        nets = self._nets()
        own = [net for net in nets if self._tool_blocks(net)]
        if own and len(nets) > 1:
            self.fail(
                f"The document holds {len(nets)} nets; an hrc pattern is written as exactly one."
            )
        document = self._own_document(nets[0]) if own else self._foreign_document(nets)
        if self.issues:
            raise FormatError(list(dict.fromkeys(self.issues)))
        return document

    def _nets(self) -> list[ET.Element]:
        namespace, _, local = self.root.tag.rpartition("}")
        namespace = namespace.removeprefix("{")
        if local != "pnml":
            raise _refuse(
                f"The root element is <{local}>, not <pnml>: this is not a PNML document."
            )
        if namespace not in ("", PNML_NAMESPACE):
            raise _refuse(
                f"The <pnml> element is in namespace {namespace!r}; PNML is {PNML_NAMESPACE!r} (or none)."
            )
        self.ns = f"{{{namespace}}}" if namespace else ""
        nets = self._children(self.root, "net")
        if not nets:
            raise _refuse("The PNML document has no <net>.")
        self.labels = {
            element_id: label
            for element in self.root.iter()
            if (element_id := element.get("id")) and (label := self._label(element))
        }
        for number, net in enumerate(nets, 1):
            if not net.get("id") and not self._tool_blocks(net):
                # The id only names the process; PIPE 5 writes none, and ours always have one.
                net.set("id", "net" if len(nets) == 1 else f"net{number}")
            self._check_net(net)
        if self.issues:
            raise FormatError(self.issues)
        return nets

    def _check_net(self, net: ET.Element) -> None:
        net_id = self._id(net, "A <net>")
        net_type = net.get("type")
        if net_type is not None and net_type not in NET_TYPES:
            self.fail(
                f"{sentence(self.named('net', net_id or '(without id)'))} has type {net_type!r};"
                f" only P/T nets ({PTNET_TYPE}, {CORE_MODEL_TYPE} or PIPE's {PIPE_NET_TYPE!r})"
                " can be read.",
                *([net_id] if net_id else []),
            )
        elif net_id and not self._tool_blocks(net):
            self._check_colours(net, net_id)

    def _check_colours(self, net: ET.Element, net_id: str) -> None:
        """PIPE's coloured nets: tokens of two colours or more cannot be read as P/T tokens."""
        used: dict[str, list[str]] = {}
        numbers = {"place": "initialMarking", "arc": "inscription"}
        for element in net.iter():
            kind = self._kind(element)
            number = self._child(element, numbers[kind]) if kind in numbers else None
            value = None if number is None else self._value(number)
            for colour, count in _colour_counts(value or ""):
                if colour is not None and count.strip() not in ("", "0"):
                    used.setdefault(colour, []).append(element.get("id", ""))
        if len(used) < 2:
            return
        colours = ", ".join(f"{colour} ({_count_words(ids)})" for colour, ids in used.items())
        self.fail(
            f"{sentence(self.named('net', net_id))} is a coloured PIPE net: its places and arcs"
            f" carry tokens of {len(used)} colours, {colours}. hrc's tokens have no colour, so"
            " only a PIPE net of one token colour can be read.",
            net_id,
        )

    # Our own files.

    def _own_document(self, net: ET.Element) -> Json:
        net_id = net.get("id", "")
        stray = [child for child in net if self._kind(child) not in (None, "page")]
        if stray:
            self.fail(f"Net {net_id} has places, transitions or arcs outside any <page>.", net_id)
        pages = [
            (page, self._contents(page, own=True))
            for page in self._children(net, "page")
            if self._id(page, "A <page>")
        ]
        names = self._names([content for _, content in pages])
        document: Json = {}
        name = self._label(net)
        if name is not None:
            document["name"] = name
        document.update(self._tool(net, "the net", net_id) or {})
        document["processes"] = [self._own_process(page, content, names) for page, content in pages]
        return document

    def _own_process(self, page: ET.Element, contents: _Contents, names: dict[str, str]) -> Json:
        page_id = page.get("id", "")
        process: Json = {"id": page_id, **(self._tool(page, f"page {page_id}", page_id) or {})}
        process["places"] = [
            self._place(node, own=True) for node in contents.nodes if node.kind == "place"
        ]
        process["transitions"] = [
            self._transition(node, own=True) for node in contents.nodes if node.kind == "transition"
        ]
        process["arcs"] = self._arcs(contents.arcs, names, own=True)
        return process

    # Files from other tools.

    def _foreign_document(self, nets: list[ET.Element]) -> Json:
        processes = [self._foreign_process(net) for net in nets]
        first = nets[0]
        label = self._label(first)
        name = label if label and label.strip() else first.get("id", "")
        return {
            "format": FORMAT,
            "name": name,
            "actors": [],
            "processes": processes,
            "constraints": [],
        }

    def _foreign_process(self, net: ET.Element) -> Json:
        contents = self._contents(net, own=False)
        names = self._names([contents])
        net_id = net.get("id", "")
        label = self._label(net)
        return {
            "id": net_id,
            "workpiece": label.strip() if label and label.strip() else net_id,
            "places": [
                self._place(node, own=False) for node in contents.nodes if node.kind == "place"
            ],
            "transitions": [
                self._transition(node, own=False)
                for node in contents.nodes
                if node.kind == "transition"
            ],
            "arcs": self._arcs(contents.arcs, names, own=False),
        }

    # Objects.

    def _contents(self, container: ET.Element, *, own: bool) -> _Contents:
        contents = _Contents()
        stack: list[Iterator[ET.Element]] = [iter(container)]
        while stack:  # iterative: nested pages may be deep
            child = next(stack[-1], None)
            if child is None:
                stack.pop()
                continue
            kind = self._kind(child)
            if kind == "page":
                self._id(child, "A <page>")
                stack.append(iter(child))
            elif kind == "arc":
                contents.arcs.append(child)
            elif kind in _REFERENCE_KINDS:
                contents.references.append(child)
            elif kind in ("place", "transition"):
                node_id = self._id(child, f"A <{kind}>")
                if node_id:
                    tool = self._tool(child, f"{kind} {node_id}", node_id) if own else None
                    contents.nodes.append(_Node(child, cast(NodeKind, kind), node_id, tool))
        return contents

    def _names(self, contents: list[_Contents]) -> dict[str, str]:
        """PNML node id -> hrc id, reference nodes resolved to the node they stand for."""
        names = {node.xml_id: node.hrc_id for part in contents for node in part.nodes}
        kinds = {node.xml_id: node.kind for part in contents for node in part.nodes}
        references = {
            ref_id: reference
            for part in contents
            for reference in part.references
            if (ref_id := self._id(reference, f"A <{self._kind(reference)}>"))
        }
        for ref_id in references:
            target = self._resolve(ref_id, references, kinds)
            if target is not None:
                names[ref_id] = names[target]
        return names

    def _resolve(
        self, ref_id: str, references: dict[str, ET.Element], kinds: dict[str, NodeKind]
    ) -> str | None:
        """The place or transition a reference node stands for; None (and an issue) if none."""
        wanted = _REFERENCE_KINDS[self._kind(references[ref_id]) or ""]
        seen = [ref_id]
        current = ref_id
        while True:
            target = references[current].get("ref")
            if not target:
                self.fail(f"Reference {current} has no ref attribute.", current)
                return None
            if kinds.get(target) == wanted:
                return target
            if target in kinds:
                self.fail(
                    f"Reference {current} must refer to a {wanted}, but {target} is a {kinds[target]}.",
                    current,
                    target,
                )
                return None
            if target not in references:
                self.fail(f"Reference {current} refers to {target}, which does not exist.", current)
                return None
            if target in seen:
                cycle = sorted(seen[seen.index(target) :])  # the same issue from each member
                self.fail(f"References {', '.join(cycle)} refer to each other in a cycle.", *cycle)
                return None
            if _REFERENCE_KINDS[self._kind(references[target]) or ""] != wanted:
                self.fail(
                    f"Reference {current} must refer to a {wanted}, but {target} does not.",
                    current,
                    target,
                )
                return None
            seen.append(target)
            current = target

    def _place(self, node: _Node, *, own: bool) -> Json:
        place: Json = {"id": node.xml_id}
        marking = self._child(node.element, "initialMarking")
        if marking is not None:
            tokens = self._count(
                marking, f"The initial marking of {self.named('place', node.xml_id)}", node.xml_id
            )
            if tokens is not None:
                place["tokens"] = tokens
        if own:
            return {**place, **(node.tool or {})}
        self._check_capacity(node)
        name = self._label(node.element)
        if name is not None and name != node.xml_id:
            place["name"] = name
        return {**place, **self._position(node.element)}

    def _check_capacity(self, node: _Node) -> None:
        capacity = self._child(node.element, "capacity")
        value = None if capacity is None else self._value(capacity)
        if value is not None and value.strip() not in ("", "0"):
            self.fail(
                f"{sentence(self.named('place', node.xml_id))} has a capacity of {value.strip()!r}"
                " in PIPE; hrc's places have no capacity (PIPE's 0 is none): remove it, or"
                " draw the limit as a place of free slots.",
                node.xml_id,
            )

    def _transition(self, node: _Node, *, own: bool) -> Json:
        transition: Json = {"id": node.xml_id}
        label = self._label(node.element)
        if own:
            if label is not None:
                transition["label"] = label
            return {**transition, **(node.tool or {})}
        if label is not None and not self._is_invisible(node.element):
            transition["label"] = label
        return {**transition, **self._position(node.element)}

    def _arcs(self, arcs: list[ET.Element], names: dict[str, str], *, own: bool) -> list[list[Any]]:
        read = (self._arc(arc, names, own=own) for arc in arcs)
        return [arc for arc in read if arc is not None]

    def _arc(self, arc: ET.Element, names: dict[str, str], *, own: bool) -> list[Any] | None:
        source, target = arc.get("source"), arc.get("target")
        arc_id = self._id(arc, f"An <arc> from {source} to {target}")
        if not arc_id:
            return None
        if not source or not target:
            self.fail(f"Arc {arc_id} needs both a source and a target.", arc_id)
            return None
        arc_words = f"arc {arc_id} ({self.named_end(source)} -> {self.named_end(target)})"
        arc_type = self._child(arc, "type")
        if not own and arc_type is not None and arc_type.get("value", "normal") != "normal":
            self.fail(
                f"{sentence(arc_words)} is a PIPE {arc_type.get('value')} arc; hrc nets have only"
                " normal arcs, each moving one token (an inhibitor arc tests a place for"
                " emptiness, which hrc's nets cannot say).",
                arc_id,
            )
            return None
        inscription = self._child(arc, "inscription")
        if inscription is not None:
            weight = self._count(inscription, f"The inscription of {arc_words}", arc_id)
            if weight is not None and weight != 1:
                self.fail(
                    f"{sentence(arc_words)} has weight {weight}; hrc nets have no"
                    " weighted arcs, each arc moves one token.",
                    arc_id,
                )
                return None
        ends = {"from": names.get(source, source), "to": names.get(target, target)}
        if own:
            ends.update(self._tool(arc, f"arc {arc_id}", arc_id) or {})
        return [ends["from"], ends["to"]]

    # Labels, numbers, positions.

    def _label(self, element: ET.Element) -> str | None:
        """The `<name><text>` of an element (PIPE's `<name><value>`); None when it has none."""
        name = self._child(element, "name")
        return None if name is None else self._value(name)

    def _value(self, element: ET.Element) -> str | None:
        """The text of an element's `<text>`, or of PIPE's `<value>`; None when it has neither."""
        text = self._child(element, "text")
        if text is None:
            text = self._child(element, "value")
        return None if text is None else text.text or ""

    def named(self, kind: str, element_id: str) -> str:
        """`place “waiting room” (P0)`, or `place P0` when it has no name but its id."""
        label = self.labels.get(element_id)
        return (
            f"{kind} “{label}” ({element_id})"
            if label and label != element_id
            else f"{kind} {element_id}"
        )

    def named_end(self, element_id: str) -> str:
        """An arc's end by its name, `“waiting room”`; its id when it has no other name."""
        label = self.labels.get(element_id)
        return f"“{label}”" if label and label != element_id else element_id

    def _count(self, element: ET.Element, where: str, element_id: str) -> int | None:
        """The whole number ≥ 0 in an element's `<text>` (a marking, an arc weight).

        PIPE writes it in `<value>`, as `3` or per token colour (`Default,3`), and an
        empty `<value>` for none; a net of several colours was refused before.
        """
        pipe = self._child(element, "text") is None and self._child(element, "value") is not None
        written = (self._value(element) or "").strip()
        counts = [count.strip() for _, count in _colour_counts(written)] if pipe else [written]
        if pipe and not written:
            return 0
        # Bounded so that int() never meets Python's limit on digits.
        if all(re.fullmatch(r"[0-9]{1,100}", count) for count in counts):
            return sum(int(count) for count in counts)
        shown = (
            "nothing"
            if not written
            else repr(written if len(written) <= 40 else written[:37] + "...")
        )
        self.fail(f"{where} must be a whole number ≥ 0, got {shown}.", element_id)
        return None

    def _position(self, element: ET.Element) -> Json:
        """An editor position from standard graphics, for files from other tools."""
        graphics = self._child(element, "graphics")
        position = None if graphics is None else self._child(graphics, "position")
        if position is None:
            return {}
        try:
            x, y = float(position.get("x", "")), float(position.get("y", ""))
        except ValueError:
            return {}  # layout only: a broken position loses the position, not the net
        if not (math.isfinite(x) and math.isfinite(y)):
            return {}
        return {"x": int(x) if x.is_integer() else x, "y": int(y) if y.is_integer() else y}

    def _is_invisible(self, element: ET.Element) -> bool:
        """pm4py and ProM mark silent transitions so; their name is then no label."""
        return any(
            block.get("tool") == "ProM" and block.get("activity") == "$invisible$"
            for block in self._children(element, "toolspecific")
        )

    # hrc toolspecific.

    def _tool_blocks(self, element: ET.Element) -> list[ET.Element]:
        return [
            block for block in self._children(element, "toolspecific") if block.get("tool") == TOOL
        ]

    def _tool(self, element: ET.Element, where: str, element_id: str) -> Json | None:
        """The JSON object in an element's hrc toolspecific; None (and an issue if broken) if none."""
        blocks = self._tool_blocks(element)
        if not blocks:
            return None
        ids = [element_id] if element_id else []
        if len(blocks) > 1:
            self.fail(
                f"The {where} has {len(blocks)} hrc toolspecific blocks; one is allowed.", *ids
            )
            return None
        version = blocks[0].get("version")
        if version != TOOL_VERSION:
            self.fail(
                f"The hrc data of the {where} is version {version!r}; this reader knows {TOOL_VERSION!r}.",
                *ids,
            )
            return None
        try:
            data = cast(object, json.loads(blocks[0].text or ""))
        except json.JSONDecodeError as exc:
            self.fail(
                f"The hrc data of the {where} is not JSON: {exc.msg} at line {exc.lineno}, column {exc.colno}.",
                *ids,
            )
            return None
        except (ValueError, RecursionError):
            self.fail(f"The hrc data of the {where} is not JSON this reader can hold.", *ids)
            return None
        if not isinstance(data, dict):
            self.fail(f"The hrc data of the {where} must be a JSON object.", *ids)
            return None
        return cast(Json, data)

    # Elements.

    def _kind(self, element: ET.Element) -> str | None:
        """The local name of a PNML element this reader knows; None for anything else."""
        if not isinstance(element.tag, str) or not element.tag.startswith(self.ns):
            return None  # comments, processing instructions, other namespaces
        local = element.tag[len(self.ns) :]
        known = ("page", "place", "transition", "arc", *_REFERENCE_KINDS)
        return local if local in known and "}" not in local else None

    def _children(self, element: ET.Element, local: str) -> list[ET.Element]:
        return [child for child in element if child.tag == self.ns + local]

    def _child(self, element: ET.Element, local: str) -> ET.Element | None:
        return next(iter(self._children(element, local)), None)

    def _id(self, element: ET.Element, what: str) -> str | None:
        element_id = element.get("id")
        if element_id:
            return element_id
        self.fail(f"{what} has no id; PNML needs one on every net, page, node and arc.")
        return None


def _colour_counts(value: str) -> list[tuple[str | None, str]]:
    """PIPE's `Default,1,Red,0` as its (colour, count) pairs; a plain `3` as one pair without colour."""
    if "," not in value:
        return [(None, value)]
    parts = value.split(",")
    if len(parts) % 2:
        return [(None, value)]  # not pairs: refused as a number that is none
    return [(parts[i].strip(), parts[i + 1]) for i in range(0, len(parts), 2)]


def _count_words(ids: list[str]) -> str:
    return f"{len(ids)} element" if len(ids) == 1 else f"{len(ids)} elements"
