"""The diagram (BPMNDI) of a BPMN export: where each pool, lane, node and edge is drawn.

`bpmn_export` places the shapes as it writes the elements, from the pattern's
layout moved into each process' pool (`Stack`); `Drawing.write` then writes
them, and routes each sequence flow, association and message flow between its
two ends' shapes.
"""

import math
import xml.etree.ElementTree as ET
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

from hrc.engine.bpmn import BPMN_NAMESPACE, BPMNDI_NAMESPACE, DC_NAMESPACE, DI_NAMESPACE

Bounds = tuple[float, float, float, float]
"""x, y, width, height."""


def point(extra: Mapping[str, Any]) -> tuple[float, float] | None:
    """A node's centre from its `layout`; None when it has none that is usable."""
    layout = extra.get("layout")
    if not isinstance(layout, dict):
        return None
    x, y = number(layout.get("x")), number(layout.get("y"))
    return None if x is None or y is None else (x, y)


def number(value: object) -> float | None:
    if isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value):
        return float(value)
    return None


@dataclass
class Shape:
    element: str
    centre: tuple[float, float]
    size: tuple[float, float]

    @property
    def bounds(self) -> tuple[float, float, float, float]:
        (x, y), (w, h) = self.centre, self.size
        return x - w / 2, y - h / 2, w, h


@dataclass
class Stack:
    """Where one process' pool is drawn: its lanes' bands of the layout, stacked from `top`."""

    moves: list[tuple[float, float, float]]
    """(top in the layout, top in the pool, height) of each of its bands."""
    lanes: dict[str | None, tuple[float, float]]
    """Band key (an actor, or None) -> (top, height) of its lane in the pool."""
    top: float
    bottom: float

    def y(self, y: float) -> float:
        """A layout y moved with the band it lies in (the nearest band when it lies in none)."""

        def distance(move: tuple[float, float, float]) -> float:
            start, _, height = move
            return max(start - y, y - (start + height), 0.0)

        start, top, height = min(self.moves, key=distance)
        return min(max(y - start + top, top), top + height)


@dataclass
class Drawing:
    """The shapes and edges of an export, collected as its elements are written."""

    shapes: list[Shape] = field(default_factory=list)
    edges: list[tuple[str, str, str]] = field(default_factory=list)
    """(flow or association id, source element, target element)."""
    message_edges: list[tuple[str, str, str]] = field(default_factory=list)
    """The same for message flows, which cross from pool to pool."""
    pool_lanes: list[tuple[str, Bounds]] = field(default_factory=list)

    def write(
        self,
        root: ET.Element,
        plane_of: str,
        pools: list[tuple[str, Bounds]],
        fresh: Callable[[str], str],
    ) -> None:
        """Appends the BPMNDiagram to `root`; `fresh` gives each DI element a new XML id."""
        diagram = ET.SubElement(root, _tag("BPMNDiagram", BPMNDI_NAMESPACE), id=fresh("diagram"))
        plane = ET.SubElement(
            diagram, _tag("BPMNPlane", BPMNDI_NAMESPACE), id=fresh("plane"), bpmnElement=plane_of
        )
        for element, bounds in [*pools, *self.pool_lanes]:
            _shape(plane, element, bounds, fresh, horizontal=True)
        by_element = {shape.element: shape for shape in self.shapes}
        for shape in self.shapes:
            _shape(plane, shape.element, shape.bounds, fresh)
        for edges, route in ((self.edges, waypoints), (self.message_edges, message_waypoints)):
            for edge_id, source, target in edges:
                edge = ET.SubElement(
                    plane,
                    _tag("BPMNEdge", BPMNDI_NAMESPACE),
                    id=fresh(f"{edge_id}_di"),
                    bpmnElement=edge_id,
                )
                for x, y in route(by_element[source], by_element[target]):
                    ET.SubElement(edge, _tag("waypoint", DI_NAMESPACE), x=_num(x), y=_num(y))


def _tag(local: str, namespace: str = BPMN_NAMESPACE) -> str:
    return f"{{{namespace}}}{local}"


def _shape(
    plane: ET.Element,
    element: str,
    bounds: Bounds,
    fresh: Callable[[str], str],
    *,
    horizontal: bool = False,
) -> None:
    shape = ET.SubElement(
        plane, _tag("BPMNShape", BPMNDI_NAMESPACE), id=fresh(f"{element}_di"), bpmnElement=element
    )
    if horizontal:
        shape.set("isHorizontal", "true")
    x, y, width, height = bounds
    ET.SubElement(
        shape,
        _tag("Bounds", DC_NAMESPACE),
        x=_num(x),
        y=_num(y),
        width=_num(width),
        height=_num(height),
    )


def waypoints(source: Shape, target: Shape) -> list[tuple[float, float]]:
    """Right side to left side, bending half-way; an edge back to the left goes round below."""
    (sx, sy), (sw, sh) = source.centre, source.size
    (tx, ty), (tw, th) = target.centre, target.size
    start, end = sx + sw / 2, tx - tw / 2
    if end > start:
        if sy == ty:
            return [(start, sy), (end, ty)]
        middle = (start + end) / 2
        return [(start, sy), (middle, sy), (middle, ty), (end, ty)]
    below = max(sy + sh / 2, ty + th / 2) + 20
    return [(sx, sy + sh / 2), (sx, below), (tx, below), (tx, ty + th / 2)]


def message_waypoints(source: Shape, target: Shape) -> list[tuple[float, float]]:
    """From the sender's side facing the catcher's pool to the catcher, bending half-way."""
    (sx, sy), (_, sh) = source.centre, source.size
    (tx, ty), (_, th) = target.centre, target.size
    down = ty > sy
    start = sy + sh / 2 if down else sy - sh / 2
    end = ty - th / 2 if down else ty + th / 2
    if sx == tx:
        return [(sx, start), (tx, end)]
    middle = (start + end) / 2
    return [(sx, start), (sx, middle), (tx, middle), (tx, end)]


def _num(value: float) -> str:
    return f"{value:.2f}".rstrip("0").rstrip(".")
