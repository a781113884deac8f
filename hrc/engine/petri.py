"""A plain place/transition net and its firing rule.

This is the structure the analysis explores and the runtime fires: the
execution net that `execution.build_execution_net` compiles from a pattern
(every task split into start and complete, constraints as extra places).
Markings are immutable mappings from place to a positive token count; places
with no token are absent, so two equal markings compare equal.

A transition may also reset places (YAWL's cancellation region): firing it
empties them, whatever they hold, without needing a token there. This is how
a terminate end or an interrupting event cancels work still under way.
"""

from collections.abc import Iterable, Iterator, Mapping
from dataclasses import dataclass, field
from typing import Literal

FiringKind = Literal["start", "complete", "silent"]


class Marking(Mapping[str, int]):
    """An immutable, hashable marking; absent places hold zero tokens."""

    __slots__ = ("_hash", "_tokens")

    def __init__(self, tokens: Mapping[str, int] | Iterable[tuple[str, int]] = ()) -> None:
        items = tokens.items() if isinstance(tokens, Mapping) else tokens
        self._tokens: dict[str, int] = {place: count for place, count in items if count > 0}
        self._hash: int | None = None

    def __getitem__(self, place: str) -> int:
        return self._tokens[place]

    def get(self, place: str, default: int = 0) -> int:  # type: ignore[override]
        return self._tokens.get(place, default)

    def __iter__(self) -> Iterator[str]:
        return iter(self._tokens)

    def __len__(self) -> int:
        return len(self._tokens)

    def __hash__(self) -> int:
        if self._hash is None:
            self._hash = hash(frozenset(self._tokens.items()))
        return self._hash

    def __eq__(self, other: object) -> bool:
        if isinstance(other, Marking):
            return self._tokens == other._tokens
        if isinstance(other, Mapping):
            return self._tokens == {p: n for p, n in other.items() if n}
        return NotImplemented

    def __repr__(self) -> str:
        inside = ", ".join(f"{p}: {n}" for p, n in sorted(self._tokens.items()))
        return f"Marking({{{inside}}})"

    def restricted(self, places: Iterable[str]) -> "Marking":
        """The marking without the given places (e.g. without constraint places)."""
        dropped = set(places)
        return Marking((p, n) for p, n in self._tokens.items() if p not in dropped)


@dataclass(frozen=True)
class NetTransition:
    """One transition of the execution net.

    `id` is unique in the net: `start:<task>`, `complete:<task>`, or the id of
    a silent transition of the pattern. `task` is the pattern transition it
    belongs to. `resets` are the places firing empties after taking `pre` and
    before putting `post` (reset arcs); they play no part in enabling.
    """

    id: str
    task: str
    kind: FiringKind
    pre: tuple[tuple[str, int], ...]
    post: tuple[tuple[str, int], ...]
    resets: tuple[str, ...] = ()

    @property
    def label(self) -> str:
        """How a person reads it in a firing sequence: `start tc1`, `complete tc1`, `t1`."""
        return self.task if self.kind == "silent" else f"{self.kind} {self.task}"

    def is_enabled(self, marking: Mapping[str, int]) -> bool:
        return all(marking.get(place, 0) >= weight for place, weight in self.pre)

    def fire(self, marking: Mapping[str, int]) -> Marking:
        """The marking after firing; the caller has checked `is_enabled`."""
        tokens = dict(marking)
        for place, weight in self.pre:
            tokens[place] -= weight
        for place in self.resets:
            tokens.pop(place, None)
        for place, weight in self.post:
            tokens[place] = tokens.get(place, 0) + weight
        return Marking(tokens)


@dataclass(frozen=True)
class Net:
    """An execution net with its initial and final marking.

    `ignored` are the places proper completion does not look at (the
    constraint places: a time constraint whose t_b never ran may leave a
    token there, and that is no fault of the model).

    `implicit` are the places (`running:` ones included) of the processes
    that complete implicitly: such a process has completed when its sink
    place holds any number of tokens (one at least) and none of its other
    places hold any, and a token elsewhere in it means it still runs, not that
    it ended with work left over.
    """

    places: tuple[str, ...]
    transitions: tuple[NetTransition, ...]
    initial: Marking
    final: Marking
    ignored: frozenset[str] = field(default_factory=frozenset)
    implicit: frozenset[str] = field(default_factory=frozenset)

    @property
    def open_ends(self) -> frozenset[str]:
        """The sink places of the processes that complete implicitly: any count ≥ 1 is final."""
        return self.implicit & frozenset(self.final)

    def enabled(self, marking: Mapping[str, int]) -> list[NetTransition]:
        """The transitions that can fire in this marking, in net order."""
        return [t for t in self.transitions if t.is_enabled(marking)]

    def is_final(self, marking: Marking) -> bool:
        """Proper completion: the final marking, constraint places aside, where an open end
        (`open_ends`) may hold more than its one token."""
        left = marking.restricted(self.ignored)
        if set(left) != set(self.final):
            return False
        return all(
            left[place] == tokens or (left[place] > tokens and place in self.implicit)
            for place, tokens in self.final.items()
        )
