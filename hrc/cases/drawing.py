"""A published pattern drawn for the supervisor pages: where each place, task, arc and constraint goes.

Positions are the document's own `layout` keys (centre coordinates on every
place and transition, lanes per actor on the document), as the editor writes
them. A document without them (published before layouts existed, imported,
written by hand) is laid out by the engine (hrc.engine.layout), in the same
actor lanes the editor would show.

The drawing is geometry only; the template turns it into SVG and the page's
script (frontend/src/supervisor/) puts the live marking on it.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import Any, Literal

from hrc.engine.execution import constraint_places
from hrc.engine.layout import SIZES, lay_out_pattern
from hrc.engine.model import Pattern, Process

# The sizes the engine's layout leaves room for.
PLACE_RADIUS = SIZES["place"][0] / 2
TASK_SIZE = SIZES["task"]
SILENT_SIZE = SIZES["silent"]  # a routing step (split, join) is a bar
MARGIN = 30.0
LINE_CHARACTERS = 15  # of a task's label at the page's font size, in a task's width

NodeKind = Literal["place", "task", "silent"]


@dataclass(frozen=True)
class Node:
    id: str
    kind: NodeKind
    x: float
    y: float
    label: str
    actor: str = ""
    """A task's performer (the pattern actor); empty for places and silent transitions."""

    @property
    def half(self) -> tuple[float, float]:
        """Half the width and height of the node's shape."""
        if self.kind == "place":
            return PLACE_RADIUS, PLACE_RADIUS
        width, height = TASK_SIZE if self.kind == "task" else SILENT_SIZE
        return width / 2, height / 2

    @property
    def width(self) -> float:
        return self.half[0] * 2

    @property
    def height(self) -> float:
        return self.half[1] * 2

    @property
    def label_lines(self) -> list[str]:
        """A task's label in at most two lines that fit its box (the full label is its title)."""
        lines: list[str] = []
        for word in self.label.split():
            if lines and len(lines[-1]) + 1 + len(word) <= LINE_CHARACTERS:
                lines[-1] += f" {word}"
            else:
                lines.append(word)
        if len(lines) > 2:
            lines = [lines[0], " ".join(lines[1:])]
        return [
            line if len(line) <= LINE_CHARACTERS else line[: LINE_CHARACTERS - 1] + "…"
            for line in lines
        ]

    def rim_towards(self, x: float, y: float) -> tuple[float, float]:
        """Where a line from the centre towards (x, y) leaves the node's shape."""
        dx, dy = x - self.x, y - self.y
        if dx == 0 and dy == 0:
            return self.x, self.y
        if self.kind == "place":
            scale = PLACE_RADIUS / math.hypot(dx, dy)
        else:
            half_w, half_h = self.half
            scale = min(half_w / abs(dx) if dx else math.inf, half_h / abs(dy) if dy else math.inf)
        return self.x + dx * scale, self.y + dy * scale


@dataclass(frozen=True)
class Arc:
    source: str
    target: str
    x1: float
    y1: float
    x2: float
    y2: float


@dataclass(frozen=True)
class ConstraintLine:
    """A constraint between two tasks, drawn as a dashed curve from t_a to t_b."""

    source: str
    target: str
    type: str
    path: str
    """SVG path data (a quadratic curve bowed to one side, so it does not hide an arc)."""
    label_x: float
    label_y: float
    places: tuple[str, ...]
    """The execution-net places the constraint adds (time, func): their tokens are shown on it."""


@dataclass(frozen=True)
class Lane:
    actor: str
    y: float
    height: float


@dataclass(frozen=True)
class NetDrawing:
    width: float
    height: float
    places: tuple[Node, ...]
    transitions: tuple[Node, ...]
    arcs: tuple[Arc, ...]
    constraints: tuple[ConstraintLine, ...]
    lanes: tuple[Lane, ...]

    @property
    def labels(self) -> dict[str, str]:
        """Each transition's label by id (its id where it has none)."""
        return {node.id: node.label for node in self.transitions}


def draw_net(pattern: Pattern) -> NetDrawing:
    """The pattern's drawing, from its layout keys where every node has one, else the engine's."""
    positions = _written_positions(pattern)
    if positions is None:
        pattern = lay_out_pattern(pattern)
        positions = _written_positions(pattern) or {}
    nodes: dict[str, Node] = {}
    for process in pattern.processes:
        for place in process.places:
            x, y = positions[place.id]
            nodes[place.id] = Node(place.id, "place", x, y, place.id)
        for transition in process.transitions:
            x, y = positions[transition.id]
            kind: NodeKind = "task" if transition.is_task else "silent"
            label = transition.label or transition.id
            nodes[transition.id] = Node(
                transition.id, kind, x, y, label, transition.performer or ""
            )
    arcs = tuple(
        _arc(nodes[source], nodes[target])
        for process in pattern.processes
        for source, target in process.arcs
    )
    constraints = tuple(_constraint_lines(pattern, nodes))
    lanes = _written_lanes(pattern)
    width, height = _extent(nodes.values(), pattern)
    return NetDrawing(
        width=width,
        height=height,
        places=tuple(n for n in nodes.values() if n.kind == "place"),
        transitions=tuple(n for n in nodes.values() if n.kind != "place"),
        arcs=arcs,
        constraints=constraints,
        lanes=lanes,
    )


def _written_positions(pattern: Pattern) -> dict[str, tuple[float, float]] | None:
    """The layout keys' centres; None unless every place and transition has one."""
    positions: dict[str, tuple[float, float]] = {}
    for process in pattern.processes:
        for node_id, extra in _elements(process):
            point = _point(extra.get("layout"))
            if point is None:
                return None
            positions[node_id] = point
    return positions


def _elements(process: Process) -> list[tuple[str, Mapping[str, Any]]]:
    """Each place's and transition's id and unknown keys, places first."""
    return [(p.id, p.extra) for p in process.places] + [
        (t.id, t.extra) for t in process.transitions
    ]


def _point(layout: Any) -> tuple[float, float] | None:
    if not isinstance(layout, Mapping):
        return None
    x, y = _number(layout.get("x")), _number(layout.get("y"))
    return None if x is None or y is None else (x, y)


def _number(value: Any) -> float | None:
    """A finite JSON number as a float; None for anything else (booleans included)."""
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        return None
    return float(value)


def _written_lanes(pattern: Pattern) -> tuple[Lane, ...]:
    layout = pattern.extra.get("layout")
    lanes = layout.get("lanes") if isinstance(layout, Mapping) else None
    if not isinstance(lanes, list):
        return ()
    drawn = []
    for lane in lanes:
        if not isinstance(lane, Mapping):
            continue
        y, height = _number(lane.get("y")), _number(lane.get("height"))
        if y is not None and height is not None:
            # The engine adds a lane with actor null for nodes of no declared actor.
            drawn.append(Lane(str(lane.get("actor") or ""), y, height))
    return tuple(drawn)


def _arc(source: Node, target: Node) -> Arc:
    x1, y1 = source.rim_towards(target.x, target.y)
    x2, y2 = target.rim_towards(source.x, source.y)
    return Arc(source.id, target.id, x1, y1, x2, y2)


def _constraint_lines(pattern: Pattern, nodes: Mapping[str, Node]) -> list[ConstraintLine]:
    added = constraint_places(pattern)
    lines = []
    for constraint in pattern.constraints:
        a, b = nodes.get(constraint.source), nodes.get(constraint.target)
        if a is None or b is None:
            continue
        ends = {constraint.source, constraint.target}
        places = tuple(
            place
            for place, meaning in added.items()
            if meaning.kind.startswith(constraint.type) and {meaning.first, meaning.second} == ends
        )
        lines.append(_bowed(a, b, constraint.type, places))
    return lines


def _bowed(a: Node, b: Node, kind: str, places: tuple[str, ...]) -> ConstraintLine:
    """A curve from a to b bowed to its left by a fifth of its length (at least 30)."""
    dx, dy = b.x - a.x, b.y - a.y
    length = math.hypot(dx, dy) or 1.0
    bow = max(30.0, length / 5)
    cx, cy = (a.x + b.x) / 2 - dy / length * bow, (a.y + b.y) / 2 + dx / length * bow
    x1, y1 = a.rim_towards(cx, cy)
    x2, y2 = b.rim_towards(cx, cy)
    path = f"M {x1:.1f} {y1:.1f} Q {cx:.1f} {cy:.1f} {x2:.1f} {y2:.1f}"
    # The curve's midpoint is halfway between the chord's midpoint and the control point.
    label_x = ((x1 + x2) / 2 + cx) / 2
    label_y = ((y1 + y2) / 2 + cy) / 2
    return ConstraintLine(a.id, b.id, kind, path, label_x, label_y, places)


def _extent(nodes: Iterable[Node], pattern: Pattern) -> tuple[float, float]:
    """The drawing's size: the written one, grown to hold every node and a margin."""
    layout = pattern.extra.get("layout")
    written = layout if isinstance(layout, Mapping) else {}
    nodes = list(nodes)
    width = max((n.x + n.half[0] for n in nodes), default=0.0) + MARGIN
    height = max((n.y + n.half[1] for n in nodes), default=0.0) + MARGIN
    return (
        max(width, _number(written.get("width")) or 0.0),
        max(height, _number(written.get("height")) or 0.0),
    )
