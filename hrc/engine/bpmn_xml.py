"""Namespaces and element helpers shared by the BPMN reader's modules."""

import xml.etree.ElementTree as ET
from collections.abc import Iterator

BPMN_NAMESPACE = "http://www.omg.org/spec/BPMN/20100524/MODEL"
HRC_NAMESPACE = "urn:hrc:bpmn:1"
"""Our attributes (actorType, constraint, workpiece, declaredPattern) and the `extra` element."""


def local_name(element: ET.Element) -> tuple[str, str]:
    """(namespace, local name) of an element; comments and processing instructions have none."""
    tag = element.tag
    if not isinstance(tag, str):
        return ("", "")
    if tag.startswith("{"):
        namespace, _, local = tag[1:].partition("}")
        return namespace, local
    return "", tag


def bpmn_name(element: ET.Element) -> str | None:
    """The local name of a BPMN element; None for elements of other namespaces."""
    namespace, local = local_name(element)
    return local if namespace == BPMN_NAMESPACE else None


def children(element: ET.Element, local: str) -> list[ET.Element]:
    tag = f"{{{BPMN_NAMESPACE}}}{local}"
    return [child for child in element if child.tag == tag]


def text_of(element: ET.Element | None) -> str:
    """The element's text with surrounding space removed; '' for none."""
    return "" if element is None else "".join(element.itertext()).strip()


def hrc_attribute(element: ET.Element, name: str) -> str | None:
    return element.get(f"{{{HRC_NAMESPACE}}}{name}")


def all_lanes(container: ET.Element) -> Iterator[ET.Element]:
    """Every lane under the container's lane sets, outer before inner."""
    stack = list(reversed(children(container, "laneSet")))
    while stack:
        lane_set = stack.pop()
        for lane in children(lane_set, "lane"):
            yield lane
            stack.extend(reversed(children(lane, "childLaneSet")))
