"""Automatic layout of a pattern in actor lanes: left to right by precedence, one band per actor.

`lay_out(document)` returns a copy of an `hrc-pattern/1` document with
`"layout": {"x": …, "y": …}` (the centre, in pixels) on every place and
transition, and on the document

    "layout": {"lanes": [{"actor": "c", "y": 0.0, "height": 120.0}, …],
               "width": …, "height": …, "sizes": {"place": {"width": 36, "height": 36}, …}}

with one lane per actor in the document's actor order (a last lane with
`"actor": null` only when some node belongs to no declared actor: a task whose
performer is unknown, or a net without tasks). Nothing else in the document
changes; `layout` keys already there are replaced.

The algorithm, deterministic (the same for any order of the lists of places,
transitions and arcs, since every tie is broken by the ids in natural order):

1. Back arcs: a depth-first search from the source places marks the arcs that
   close loops; the rest of the net is acyclic.
2. Columns: longest-path layering over that acyclic net, so every arc that is
   not a back arc points strictly right. A time constraint (a, b) also puts b
   at least one task column right of a, unless the net already orders them the
   other way (the check reports that; the drawing must not hide it).
3. Lanes: a task goes to its performer's lane. Places and silent transitions go
   where most of their neighbours are, nearest tasks first (rounds outward from
   the tasks); a tie goes to the actor listed first.
4. Rows: nodes sharing a lane and a column are stacked in sub-rows, so no two
   nodes ever overlap and the lane grows to fit. A few barycentre sweeps keep
   parallel branches in steady rows, which removes most crossings.

Pure Python and no Django, like the rest of the engine, so the server lays
out imported models (PNML, BPMN) with the same code the editor asks for.
"""

import heapq
import math
import re
from collections import defaultdict
from collections.abc import Iterable
from dataclasses import dataclass, field, replace
from typing import Any, Literal

from hrc.engine.document import read_pattern, write_pattern
from hrc.engine.model import Pattern, Place, Process, Transition

NodeKind = Literal["place", "task", "silent"]

# Node sizes the layout reserves room for; the editor draws inside them.
PLACE_SIZE = 36.0
TASK_WIDTH = 100.0
TASK_HEIGHT = 60.0
SILENT_WIDTH = 20.0
"""A silent transition is drawn as a bar, the Petri net convention for a routing step."""
SILENT_HEIGHT = 60.0
SIZES: dict[NodeKind, tuple[float, float]] = {
    "place": (PLACE_SIZE, PLACE_SIZE),
    "task": (TASK_WIDTH, TASK_HEIGHT),
    "silent": (SILENT_WIDTH, SILENT_HEIGHT),
}

LANE_HEADER_WIDTH = 40.0
"""Room at the left of every lane for the actor's name."""
MARGIN = 30.0
"""Space between the lane header and the first column, and after the last."""
COLUMN_GAP = 40.0
"""Horizontal space between the widest nodes of two neighbouring columns."""
ROW_HEIGHT = 90.0
"""One sub-row of a lane: the tallest node (60) and the gap below it."""
LANE_PADDING = 15.0
"""Space above the first and below the last sub-row of a lane."""
SWEEPS = 4
"""Barycentre sweeps (alternately left to right and right to left)."""
CONSTRAINT_SPAN = 2
"""Columns between the two tasks of a time constraint: a task, a place, a task."""
# Each time constraint costs a search of the graph drawn so far (adding its span must not
# close a cycle). Past this many nodes visited in all, the remaining constraints are drawn
# without their span, so a document with thousands of them is laid out in bounded time.
CONSTRAINT_SEARCH_STEPS = 1_000_000


def lay_out(document: object) -> dict[str, Any]:
    """A laid-out copy of a document; raises document.FormatError when it is not `hrc-pattern/1`.

    The document may break the model's rules (unknown nodes, duplicate ids, no
    workflow net): the layout draws what is there.
    """
    return write_pattern(lay_out_pattern(read_pattern(document)))


def lay_out_pattern(pattern: Pattern) -> Pattern:
    """The pattern with `layout` in the extras of every place and transition, and of the pattern."""
    plan = _Plan(pattern)
    positions = plan.positions()
    processes = []
    for index, process in enumerate(pattern.processes):
        places = tuple(
            replace(p, extra=_with_layout(p.extra, positions[index, "place", p.id]))
            for p in process.places
        )
        transitions = tuple(
            replace(t, extra=_with_layout(t.extra, positions[index, "transition", t.id]))
            for t in process.transitions
        )
        processes.append(replace(process, places=places, transitions=transitions))
    extra = {**pattern.extra, "layout": plan.document_layout()}
    return replace(pattern, processes=tuple(processes), extra=extra)


def is_laid_out(pattern: Pattern) -> bool:
    """Whether every node has a position and every actor a lane, as `lay_out` writes them."""
    layout = pattern.extra.get("layout")
    if not isinstance(layout, dict) or not _is_number(layout.get("width")):
        return False
    lanes = layout.get("lanes")
    if not isinstance(lanes, list) or not all(
        isinstance(lane, dict) and _is_number(lane.get("y")) and _is_number(lane.get("height"))
        for lane in lanes
    ):
        return False
    drawn = {lane.get("actor") for lane in lanes}
    if any(actor.id not in drawn for actor in pattern.actors):
        return False
    extras = [p.extra for process in pattern.processes for p in process.places]
    extras += [t.extra for process in pattern.processes for t in process.transitions]
    return all(
        isinstance(point := extra.get("layout"), dict)
        and _is_number(point.get("x"))
        and _is_number(point.get("y"))
        for extra in extras
    )


def _is_number(value: object) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value)


def natural_key(text: str) -> tuple[tuple[tuple[int, int, str], ...], str]:
    """Sorts "p2" before "p10": runs of digits compare as numbers, the rest as text."""
    parts = re.split(r"([0-9]+)", text)
    numbered = tuple(
        (0, int(part), part) if part.isascii() and part.isdigit() else (1, 0, part)
        for part in parts
        if part
    )
    return numbered, text


def _with_layout(extra: Any, position: tuple[float, float]) -> dict[str, Any]:
    return {**extra, "layout": {"x": position[0], "y": position[1]}}


@dataclass
class _Node:
    index: int
    id: str
    process: int
    element: Literal["place", "transition"]
    kind: NodeKind
    performer: str | None
    successors: list[int] = field(default_factory=list)
    predecessors: list[int] = field(default_factory=list)
    order: tuple[Any, ...] = ()
    column: int = 0
    lane: int = 0
    row: int = 0
    preorder: int = 0


class _Plan:
    """The layout of one pattern, computed once in the steps of the module docstring."""

    def __init__(self, pattern: Pattern) -> None:
        self.pattern = pattern
        self.actors = list(dict.fromkeys(actor.id for actor in pattern.actors))
        self.nodes: list[_Node] = []
        self.by_id: dict[str, int] = {}
        """Node index of each id, first occurrence in the document (arcs and constraints name ids)."""
        for process_index, process in enumerate(pattern.processes):
            self._add_process(process_index, process)
        for node in self.nodes:
            node.order = (node.process, natural_key(node.id), node.element)
        self.back: set[tuple[int, int]] = set()
        self._find_back_arcs()
        self.forward: dict[int, list[tuple[int, int]]] = defaultdict(list)
        """Acyclic edges with their minimum length in columns: net arcs and time constraints."""
        self.search_steps = CONSTRAINT_SEARCH_STEPS
        self._build_forward_edges()
        self._assign_columns()
        self.null_lane = len(self.actors)
        self._assign_lanes()
        self.lane_rows: dict[int, int] = {}
        self._assign_rows()

    # The graph.

    def _add_process(self, process_index: int, process: Process) -> None:
        local: dict[str, int] = {}
        elements: list[Place | Transition] = [*process.places, *process.transitions]
        for element in elements:
            if isinstance(element, Place):
                kind: NodeKind = "place"
                performer = None
            else:
                kind = "task" if element.is_task else "silent"
                performer = element.performer
            node = _Node(
                index=len(self.nodes),
                id=element.id,
                process=process_index,
                element="place" if isinstance(element, Place) else "transition",
                kind=kind,
                performer=performer,
            )
            self.nodes.append(node)
            local.setdefault(element.id, node.index)
            self.by_id.setdefault(element.id, node.index)
        seen: set[tuple[int, int]] = set()
        for source, target in process.arcs:
            if source not in local or target not in local:
                continue  # an arc to a node elsewhere or nowhere: the rules report it
            arc = (local[source], local[target])
            if arc[0] == arc[1] or arc in seen:
                continue
            seen.add(arc)
            self.nodes[arc[0]].successors.append(arc[1])
            self.nodes[arc[1]].predecessors.append(arc[0])

    def _sorted(self, indexes: Iterable[int]) -> list[int]:
        return sorted(indexes, key=lambda i: self.nodes[i].order)

    def _find_back_arcs(self) -> None:
        """Depth-first search from the sources, then from anything left (a net that is all loop)."""
        sources = [n.index for n in self.nodes if not n.predecessors]
        roots = self._sorted(sources) + self._sorted(n.index for n in self.nodes)
        state = [0] * len(self.nodes)  # 0 unseen, 1 on the stack, 2 done
        counter = 0
        for root in roots:
            if state[root]:
                continue
            state[root] = 1
            self.nodes[root].preorder = counter
            counter += 1
            stack = [(root, iter(self._sorted(self.nodes[root].successors)))]
            while stack:
                node, successors = stack[-1]
                successor = next(successors, None)
                if successor is None:
                    state[node] = 2
                    stack.pop()
                elif state[successor] == 1:
                    self.back.add((node, successor))
                elif state[successor] == 0:
                    state[successor] = 1
                    self.nodes[successor].preorder = counter
                    counter += 1
                    stack.append((successor, iter(self._sorted(self.nodes[successor].successors))))

    def _build_forward_edges(self) -> None:
        for node in self.nodes:
            for successor in node.successors:
                if (node.index, successor) not in self.back:
                    self.forward[node.index].append((successor, 1))
        time_constraints = sorted(
            {
                (self.by_id[c.source], self.by_id[c.target])
                for c in self.pattern.constraints
                if c.type == "time" and c.source in self.by_id and c.target in self.by_id
            },
            key=lambda pair: (self.nodes[pair[0]].order, self.nodes[pair[1]].order),
        )
        for a, b in time_constraints:
            if a != b and not self._reaches(b, a):
                self.forward[a].append((b, CONSTRAINT_SPAN))

    def _reaches(self, start: int, goal: int) -> bool:
        """Whether `goal` can be reached from `start`; True, to be safe, once the steps are spent."""
        seen, stack = {start}, [start]
        while stack:
            self.search_steps -= 1
            if self.search_steps < 0:
                return True
            node = stack.pop()
            if node == goal:
                return True
            for successor, _ in self.forward.get(node, ()):
                if successor not in seen:
                    seen.add(successor)
                    stack.append(successor)
        return False

    # Columns, lanes, rows.

    def _assign_columns(self) -> None:
        """Longest path from the sources, in a topological order with ties by id."""
        incoming = [0] * len(self.nodes)
        for edges in self.forward.values():
            for target, _ in edges:
                incoming[target] += 1
        ready = [(n.order, n.index) for n in self.nodes if incoming[n.index] == 0]
        heapq.heapify(ready)
        while ready:
            _, index = heapq.heappop(ready)
            for target, span in self.forward.get(index, ()):
                node = self.nodes[target]
                node.column = max(node.column, self.nodes[index].column + span)
                incoming[target] -= 1
                if incoming[target] == 0:
                    heapq.heappush(ready, (node.order, target))

    def _assign_lanes(self) -> None:
        lane_of_actor = {actor: index for index, actor in enumerate(self.actors)}
        lanes: dict[int, int] = {}
        for node in self.nodes:
            if node.kind == "task":
                # An unknown performer gets the spare lane, not another actor's.
                lanes[node.index] = lane_of_actor.get(node.performer or "", self.null_lane)
        # Rounds outward from the tasks; each round sees only the lanes fixed before it,
        # so the result does not depend on the order nodes are visited in.
        while True:
            decided: dict[int, int] = {}
            for node in self.nodes:
                if node.index in lanes:
                    continue
                votes: dict[int, int] = defaultdict(int)
                for neighbour in (*node.predecessors, *node.successors):
                    if neighbour in lanes:
                        votes[lanes[neighbour]] += 1
                if votes:
                    decided[node.index] = min(votes, key=lambda lane: (-votes[lane], lane))
            if not decided:
                break
            lanes.update(decided)
        for node in self.nodes:
            node.lane = lanes.get(node.index, self.null_lane)

    def _assign_rows(self) -> None:
        groups: dict[tuple[int, int], list[int]] = defaultdict(list)
        for node in self.nodes:
            groups[node.lane, node.column].append(node.index)
        for key, members in groups.items():
            members.sort(key=lambda i: (self.nodes[i].preorder, self.nodes[i].order))
            for row, index in enumerate(members):
                self.nodes[index].row = row
            self.lane_rows[key[0]] = max(self.lane_rows.get(key[0], 1), len(members))
        neighbours = {
            node.index: [
                other
                for other in (*node.predecessors, *node.successors)
                if (node.index, other) not in self.back and (other, node.index) not in self.back
            ]
            for node in self.nodes
        }
        lanes_of: dict[int, list[int]] = defaultdict(list)
        for lane, column in sorted(groups):
            lanes_of[column].append(lane)
        columns = sorted(lanes_of)
        for sweep in range(SWEEPS):
            for column in columns if sweep % 2 == 0 else reversed(columns):
                for lane in lanes_of[column]:
                    self._settle(groups[lane, column], neighbours)

    def _settle(self, members: list[int], neighbours: dict[int, list[int]]) -> None:
        """Orders one lane's nodes of one column by the rows of their neighbours in the lane."""
        lane = self.nodes[members[0]].lane
        wanted: dict[int, float] = {}
        for index in members:
            near = [
                self.nodes[other].row
                for other in neighbours[index]
                if self.nodes[other].lane == lane
            ]
            wanted[index] = sum(near) / len(near) if near else float(self.nodes[index].row)
        members.sort(key=lambda i: (wanted[i], self.nodes[i].row, self.nodes[i].preorder))
        last = self.lane_rows[lane] - 1
        rows: list[int] = []
        for position, index in enumerate(members):
            preferred = min(max(_round(wanted[index]), 0), last)
            rows.append(max(preferred, rows[-1] + 1) if position else preferred)
        # Pushed past the lane's last row: move up from the bottom (the lane never grows here).
        ceiling = last
        for position in range(len(rows) - 1, -1, -1):
            rows[position] = min(rows[position], ceiling)
            ceiling = rows[position] - 1
        for index, row in zip(members, rows, strict=True):
            self.nodes[index].row = row

    # Coordinates.

    def lanes(self) -> list[str | None]:
        """The lanes top to bottom: each actor, then the spare lane if a node is in it."""
        lanes: list[str | None] = list(self.actors)
        if any(node.lane == self.null_lane for node in self.nodes):
            lanes.append(None)
        return lanes

    def lane_bands(self) -> list[tuple[float, float]]:
        """(top, height) of each lane."""
        bands, top = [], 0.0
        for index in range(len(self.lanes())):
            height = 2 * LANE_PADDING + self.lane_rows.get(index, 1) * ROW_HEIGHT
            bands.append((top, height))
            top += height
        return bands

    def column_centres(self) -> list[float]:
        count = max((node.column for node in self.nodes), default=-1) + 1
        widths = [0.0] * count
        for node in self.nodes:
            widths[node.column] = max(widths[node.column], SIZES[node.kind][0])
        centres, left = [], LANE_HEADER_WIDTH + MARGIN
        for width in widths:
            centres.append(left + width / 2)
            left += width + COLUMN_GAP
        return centres

    def width(self) -> float:
        centres = self.column_centres()
        if not centres:
            return LANE_HEADER_WIDTH + 2 * MARGIN
        last = max(
            (SIZES[n.kind][0] for n in self.nodes if n.column == len(centres) - 1), default=0.0
        )
        return centres[-1] + last / 2 + MARGIN

    def positions(self) -> dict[tuple[int, str, str], tuple[float, float]]:
        """The centre of each node, by (process index, "place" | "transition", id)."""
        bands = self.lane_bands()
        centres = self.column_centres()
        positions: dict[tuple[int, str, str], tuple[float, float]] = {}
        for node in self.nodes:
            top = bands[node.lane][0]
            y = top + LANE_PADDING + node.row * ROW_HEIGHT + ROW_HEIGHT / 2
            # A duplicate id keeps the first node's place; the rules report the duplicate.
            positions.setdefault((node.process, node.element, node.id), (centres[node.column], y))
        return positions

    def document_layout(self) -> dict[str, Any]:
        bands = self.lane_bands()
        return {
            "lanes": [
                {"actor": actor, "y": top, "height": height}
                for actor, (top, height) in zip(self.lanes(), bands, strict=True)
            ],
            "width": self.width(),
            "height": sum(height for _, height in bands),
            "sizes": {
                kind: {"width": width, "height": height} for kind, (width, height) in SIZES.items()
            },
        }


def _round(value: float) -> int:
    """Half rounds down, whatever the platform's banker's rounding would do."""
    return int(value + 0.5) if value - int(value) != 0.5 else int(value)
