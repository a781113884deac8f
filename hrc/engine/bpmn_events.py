"""What BPMN events become: the keys of their transitions (`message`, `send`, `timer`, `guard`).

`bpmn_scopes.ProcessReader` reads each event's definition with `trigger_of`
and gives its transition the keys `event_keys` returns; `bpmn.py`'s docstring
gives the mapping.
"""

import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from typing import Any, Protocol

from hrc.engine.bpmn_conditions import translate
from hrc.engine.bpmn_net import FlowNode
from hrc.engine.bpmn_xml import bpmn_name, children, text_of

Json = dict[str, Any]

CORRELATION_SEND = {"case": "=case.id"}
CORRELATION_AWAIT = {"case": "case.id"}
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


def trigger_of(reading: Reading, element: ET.Element, node: FlowNode) -> Trigger | None:
    """The event's first definition, its own or one at the root it refers to; None for none.

    A reference to a definition the file lacks is a Trigger of kind `reference`.
    """
    for given in element:
        child = given
        if bpmn_name(given) == "eventDefinitionRef":
            # A definition at the file's root, shared by several events.
            shared = reading.event_definition(text_of(given))
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
            name = reading.definition_name(reference)
            if kind == "link":
                name = child.get("name") or node.name
            return Trigger(kind, child, name)
    return None


def event_keys(
    reading: Reading, node: FlowNode, trigger: Trigger | None, *, catching: bool, what: str
) -> None:
    """Adds to the node's keys what its trigger means: a message awaited or sent, a timer, ..."""
    if trigger is None:
        return
    kind = trigger.kind
    keys: Json = {}
    if kind == "message":
        if catching:
            name = reading.message_in(node.xml_id)
            if node.kind == "startEvent" and name is None:
                keys["bpmn"] = "message start"
            else:
                keys["message"] = awaited(name or trigger.name or node.name or node.xml_id)
        else:
            flows_out = reading.messages_out(node.xml_id)
            named = flows_out[0] if flows_out else trigger.name or node.name or node.xml_id
            keys["send"] = sent(named)
    elif kind == "signal":
        name = f"signal:{trigger.name or node.name or node.xml_id}"
        if not catching:
            keys["send"] = sent(name)
        elif node.kind == "startEvent" and not reading.signal_thrown(name):
            keys["bpmn"] = "signal start"
        else:
            keys["message"] = awaited(name)
    elif kind == "timer":
        keys.update(_timer(trigger.element, node, what))
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
        keys["message"] = awaited(f"{kind}:{trigger.name or node.name or node.xml_id}")
    elif kind in ("error", "escalation") and catching:
        keys["bpmn"] = f"{kind} start"
    sent_extra = reading.messages_out(node.xml_id)
    if not catching and "send" not in keys and sent_extra:
        keys["send"] = sent(sent_extra[0])
    node.keys.update(keys)


def _timer(definition: ET.Element, node: FlowNode, what: str) -> Json:
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


def task_messages(reading: Reading, node: FlowNode, message_ref: str | None) -> None:
    """A receive task waits for its message: the one a message flow brings, else the one it
    names; a task a message flow leaves sends it.

    Other tasks a message flow reaches do not wait: BPMN gives only receive
    tasks (and catch events) that meaning.
    """
    if node.kind == "receiveTask":
        received = reading.message_in(node.xml_id) or reading.definition_name(message_ref)
        node.receive = awaited(received or node.name or node.xml_id)
    flows_out = reading.messages_out(node.xml_id)
    if flows_out:
        node.keys.setdefault("send", sent(flows_out[0]))


def awaited(name: str) -> Json:
    """The `message` key of a transition waiting for a message of this case."""
    return {"name": name, "correlation": dict(CORRELATION_AWAIT)}


def sent(name: str) -> Json:
    """The `send` key of a transition sending a message to this case."""
    return {"name": name, "correlation": dict(CORRELATION_SEND)}
