"""The collaboration pattern model CP = (N, A, w, actassign, wpassign, tperformer, constr).

Frozen dataclasses, one per element of an `hrc-pattern/1` document. Each
keeps the keys this version does not know in `extra`, so that a read and a
write give back the editor's layout and each task's configuration unchanged.
A coexistence pattern is the same shape with several processes.
"""

from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from functools import cached_property
from typing import Any, Literal, TypeVar

ActorType = Literal["cobot", "operator"]
ConstraintType = Literal["time", "space", "func"]
Completion = Literal["proper", "implicit"]
PatternName = Literal["synchronized", "cooperation", "collaboration", "coexistence"]

ACTOR_TYPES: tuple[ActorType, ...] = ("cobot", "operator")
CONSTRAINT_TYPES: tuple[ConstraintType, ...] = ("time", "space", "func")
COMPLETIONS: tuple[Completion, ...] = ("proper", "implicit")
PATTERN_NAMES: tuple[PatternName, ...] = (
    "synchronized",
    "cooperation",
    "collaboration",
    "coexistence",
)

Extra = Mapping[str, Any]


@dataclass(frozen=True)
class Actor:
    id: str
    type: ActorType
    extra: Extra = field(default_factory=dict, compare=False)


@dataclass(frozen=True)
class Place:
    id: str
    tokens: int | None = None
    """The initial marking as written; None means "default" (see Process.initial_marking)."""
    extra: Extra = field(default_factory=dict, compare=False)


@dataclass(frozen=True)
class Transition:
    id: str
    performer: str | None = None
    """The actor who performs this task; None for a silent routing step (split, join)."""
    label: str | None = None
    extra: Extra = field(default_factory=dict, compare=False)

    @property
    def is_task(self) -> bool:
        return self.performer is not None


@dataclass(frozen=True)
class Process:
    """One Petri net N = (P, T, F) with its actors (actassign) and workpiece (wpassign)."""

    id: str
    workpiece: str | None
    actors: tuple[str, ...]
    places: tuple[Place, ...]
    transitions: tuple[Transition, ...]
    arcs: tuple[tuple[str, str], ...]
    extra: Extra = field(default_factory=dict, compare=False)

    @property
    def completes_implicitly(self) -> bool:
        """Whether a case of this process has completed once all its tokens lie in its sink place,
        however many (`"completion": "implicit"`, BPMN's rule: each end event consumes its token),
        rather than when exactly one does. A value other than COMPLETIONS is a rule's to report."""
        return self.extra.get("completion") == "implicit"

    def source_places(self) -> list[str]:
        """Places with no incoming arc, in document order."""
        targets = {target for _, target in self.arcs}
        return [p.id for p in self.places if p.id not in targets]

    def sink_places(self) -> list[str]:
        """Places with no outgoing arc, in document order."""
        sources = {source for source, _ in self.arcs}
        return [p.id for p in self.places if p.id not in sources]

    def initial_marking(self) -> dict[str, int]:
        """The written tokens; where no place says any, one token in each source place."""
        written = {p.id: p.tokens for p in self.places if p.tokens is not None}
        if written:
            return {place: tokens for place, tokens in written.items() if tokens > 0}
        return {place: 1 for place in self.source_places()}


@dataclass(frozen=True)
class Constraint:
    source: str
    """t_a, written `from` in the document."""
    target: str
    """t_b, written `to` in the document."""
    type: str
    """One of CONSTRAINT_TYPES in a valid model; kept as written so the rules can report it."""
    extra: Extra = field(default_factory=dict, compare=False)

    @property
    def elements(self) -> list[str]:
        return [self.source, self.target]


@dataclass(frozen=True)
class Pattern:
    name: str
    actors: tuple[Actor, ...]
    processes: tuple[Process, ...]
    constraints: tuple[Constraint, ...]
    declared_pattern: str | None = None
    extra: Extra = field(default_factory=dict, compare=False)

    def actor(self, actor_id: str) -> Actor | None:
        return self._actor_by_id.get(actor_id)

    def transitions(self) -> Iterator[tuple[Process, Transition]]:
        for process in self.processes:
            for transition in process.transitions:
                yield process, transition

    def transition(self, transition_id: str) -> Transition | None:
        return self._transition_by_id.get(transition_id)

    def process_of(self, node_id: str) -> Process | None:
        """The process whose net holds this place or transition; None if none does."""
        return self._process_by_node.get(node_id)

    # Indexes for the lookups above, which rules and wording make once per element:
    # a linear search each time made a check quadratic in the size of the document.
    # Where an id is used twice (a rule reports it), the first element wins.

    @cached_property
    def _actor_by_id(self) -> dict[str, Actor]:
        return _first_by_id((a.id, a) for a in self.actors)

    @cached_property
    def _transition_by_id(self) -> dict[str, Transition]:
        return _first_by_id((t.id, t) for _, t in self.transitions())

    @cached_property
    def _process_by_node(self) -> dict[str, Process]:
        return _first_by_id(
            (node_id, process)
            for process in self.processes
            for node_id in (*(p.id for p in process.places), *(t.id for t in process.transitions))
        )


Value = TypeVar("Value")


def _first_by_id(pairs: Iterator[tuple[str, Value]]) -> dict[str, Value]:
    index: dict[str, Value] = {}
    for key, value in pairs:
        index.setdefault(key, value)
    return index
