"""Soundness of an execution net: deadlocks, proper completion, dead tasks, boundedness.

The net is first reduced (`reduction.reduce_net`), then its reachable
markings are explored breadth first, so the first marking found with a
fault is one at the end of a shortest firing sequence, and that sequence,
expanded back into the original firings, is the witness shown to the
engineer (shortest up to the steps the reduction takes at once: a chain of
firings that nothing can interrupt is shown whole). Exploration stops at `max_markings`; whatever was found by then is
reported, and a verdict that needs the whole space becomes "too large to
decide" instead of a hang.
"""

from collections import deque
from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import Literal

from hrc.engine.graph import reachable
from hrc.engine.petri import Marking, Net
from hrc.engine.reduction import ReducedNet, reduce_net

DEFAULT_MAX_MARKINGS = 200_000

FaultKind = Literal["deadlock", "livelock", "improper", "dead", "unbounded"]

_State = tuple[int, ...]


@dataclass(frozen=True)
class Fault:
    """One way the model goes wrong, with the firing sequence that shows it."""

    kind: FaultKind
    marking: Marking | None
    """The marking reached by the witness; None for a dead transition."""
    witness: tuple[str, ...] = ()
    """Ids of the execution net's transitions, fired from the initial marking."""
    transition: str | None = None
    """For `dead`: the transition that can never fire."""
    place: str | None = None
    """For `unbounded`: a place that grows."""
    repeat: tuple[str, ...] = ()
    """For `unbounded`: the firings that, repeated, add tokens each time."""


@dataclass(frozen=True)
class Analysis:
    decided: bool
    """False when exploration hit the cap before every fault kind could be ruled out."""
    faults: tuple[Fault, ...]
    markings: int
    reduced_transitions: int
    stats: dict[str, int] = field(default_factory=dict)

    @property
    def sound(self) -> bool | None:
        if self.faults:
            return False
        return True if self.decided else None


class _Explorer:
    """Breadth-first exploration of a reduced net over markings as tuples of counts."""

    def __init__(self, net: Net, reduced: ReducedNet, max_markings: int) -> None:
        self.net = net
        self.reduced = reduced
        self.max_markings = max_markings
        self.index = {place: i for i, place in enumerate(reduced.places)}
        self.pre = [[(self.index[p], w) for p, w in t.pre] for t in reduced.transitions]
        self.delta = [self._delta(t.pre, t.post) for t in reduced.transitions]
        # Candidates per marked place, so a marking only tests transitions it can feed.
        self.consumers: list[list[int]] = [[] for _ in reduced.places]
        self.always = [i for i, pre in enumerate(self.pre) if not pre]
        for i, pre in enumerate(self.pre):
            if pre:
                self.consumers[min(pre)[0]].append(i)
        self.ignored = {self.index[p] for p in net.ignored if p in self.index}
        self.final = self._state(net.final)
        self.cyclic = _has_cycle(reduced)
        self.parent: dict[_State, tuple[_State, int] | None] = {}
        self.order: list[_State] = []
        self.edges: dict[_State, list[tuple[int, _State]]] = {}
        self.unbounded: Fault | None = None

    def _delta(
        self, pre: tuple[tuple[str, int], ...], post: tuple[tuple[str, int], ...]
    ) -> list[tuple[int, int]]:
        change: dict[int, int] = {}
        for place, weight in pre:
            change[self.index[place]] = change.get(self.index[place], 0) - weight
        for place, weight in post:
            change[self.index[place]] = change.get(self.index[place], 0) + weight
        return [(i, d) for i, d in change.items() if d]

    def _state(self, marking: Marking) -> _State:
        tokens = [0] * len(self.index)
        for place, count in marking.items():
            tokens[self.index[place]] = count
        return tuple(tokens)

    def marking(self, state: _State) -> Marking:
        return Marking((self.reduced.places[i], n) for i, n in enumerate(state) if n)

    def successors(self, state: _State) -> Iterator[tuple[int, _State]]:
        candidates = list(self.always)
        for i, count in enumerate(state):
            if count:
                candidates.extend(self.consumers[i])
        for t in sorted(candidates):
            if all(state[i] >= w for i, w in self.pre[t]):
                tokens = list(state)
                for i, d in self.delta[t]:
                    tokens[i] += d
                yield t, tuple(tokens)

    def explore(self) -> bool:
        """Fills `order`, `parent` and `edges`; False when the cap stopped it early."""
        start = self._state(self.net.initial)
        self.parent[start] = None
        self.order.append(start)
        queue = deque([start])
        while queue:
            state = queue.popleft()
            out = self.edges[state] = []
            for t, successor in self.successors(state):
                out.append((t, successor))
                if successor in self.parent:
                    continue
                self.parent[successor] = (state, t)
                if self.cyclic and self.unbounded is None:
                    self.unbounded = self._covering(successor)
                    if self.unbounded is not None:
                        return True  # An unbounded space has no end: what else it holds is moot.
                self.order.append(successor)
                if len(self.order) >= self.max_markings:
                    return False
                queue.append(successor)
        return True

    def _covering(self, state: _State) -> Fault | None:
        """An ancestor this marking strictly covers proves a place unbounded (Karp–Miller)."""
        total = sum(state)
        link = self.parent[state]
        while link is not None:
            ancestor, _ = link
            if sum(ancestor) < total and all(a <= b for a, b in zip(ancestor, state, strict=True)):
                grown = next(
                    i for i, (a, b) in enumerate(zip(ancestor, state, strict=True)) if b > a
                )
                prefix = self.path(ancestor)
                return Fault(
                    "unbounded",
                    self.marking(state),
                    witness=prefix,
                    place=self.reduced.places[grown],
                    repeat=self.path(state)[len(prefix) :],
                )
            link = self.parent[ancestor]
        return None

    def path(self, state: _State) -> tuple[str, ...]:
        """The original firings of the breadth-first (shortest) path to `state`."""
        steps: list[int] = []
        link = self.parent[state]
        while link is not None:
            state, t = link
            steps.append(t)
            link = self.parent[state]
        return tuple(f for t in reversed(steps) for f in self.reduced.transitions[t].firings)

    def is_final(self, state: _State) -> bool:
        return all(
            n == f or i in self.ignored
            for i, (n, f) in enumerate(zip(state, self.final, strict=True))
        )

    def is_improper(self, state: _State) -> bool:
        """The end is marked but something else (apart from constraint places) still is too."""
        covers = all(n >= f for n, f in zip(state, self.final, strict=True))
        return covers and not self.is_final(state)


def analyse(net: Net, max_markings: int = DEFAULT_MAX_MARKINGS) -> Analysis:
    """Decides soundness and boundedness of an execution net; see the module docstring."""
    reduced = reduce_net(net)
    explorer = _Explorer(net, reduced, max_markings)
    complete = explorer.explore()
    faults: list[Fault] = []
    if explorer.unbounded is not None:
        faults.append(explorer.unbounded)
    else:
        faults.extend(_local_faults(explorer))
        if complete:
            faults.extend(_global_faults(explorer))
    stats = {
        "net_places": len(net.places),
        "net_transitions": len(net.transitions),
        "reduced_places": len(reduced.places),
        "reduced_transitions": len(reduced.transitions),
        "markings": len(explorer.order),
    }
    return Analysis(complete, tuple(faults), len(explorer.order), len(reduced.transitions), stats)


def _local_faults(explorer: _Explorer) -> Iterator[Fault]:
    """Faults a single marking shows: the first deadlock and the first improper end, in BFS order."""
    deadlock: _State | None = None
    improper: _State | None = None
    for state in explorer.order:
        if state not in explorer.edges:
            break  # Past the cap: not expanded, so "no successor" would be a lie.
        dead = not explorer.edges[state]
        if (
            deadlock is None
            and dead
            and not explorer.is_final(state)
            and not explorer.is_improper(state)
        ):
            deadlock = state
        if improper is None and explorer.is_improper(state):
            improper = state
    if deadlock is not None:
        yield Fault("deadlock", explorer.marking(deadlock), explorer.path(deadlock))
    if improper is not None:
        yield Fault("improper", explorer.marking(improper), explorer.path(improper))


def _global_faults(explorer: _Explorer) -> Iterator[Fault]:
    """Faults that need the whole space: no way to the end (livelock), transitions that never fire."""
    reverse: dict[_State, list[_State]] = {state: [] for state in explorer.order}
    for state, out in explorer.edges.items():
        for _, successor in out:
            reverse[successor].append(state)
    can_finish = reachable([s for s in explorer.order if explorer.is_final(s)], reverse)
    can_end = reachable([s for s in explorer.order if not explorer.edges[s]], reverse)
    # A livelock: the case runs on but can neither finish nor even get stuck.
    looping = next((s for s in explorer.order if s not in can_finish and s not in can_end), None)
    if looping is not None:
        yield Fault("livelock", explorer.marking(looping), explorer.path(looping))
    fired = {
        firing
        for out in explorer.edges.values()
        for t, _ in out
        for firing in explorer.reduced.transitions[t].firings
    }
    for transition in explorer.net.transitions:
        if transition.id not in fired:
            yield Fault("dead", None, transition=transition.id)


def _has_cycle(net: ReducedNet) -> bool:
    """Whether the net's graph has a cycle; an acyclic net is bounded, so the cover test can be skipped."""
    successors: dict[str, set[str]] = {}
    for i, t in enumerate(net.transitions):
        node = f"#{i}"
        successors[node] = {p for p, _ in t.post}
        for place, _ in t.pre:
            successors.setdefault(place, set()).add(node)
    colour: dict[str, int] = {}
    for root in successors:
        if root in colour:
            continue
        stack = [(root, iter(successors[root]))]
        colour[root] = 1
        while stack:
            node, children = stack[-1]
            child = next(children, None)
            if child is None:
                colour[node] = 2
                stack.pop()
            elif colour.get(child) == 1:
                return True
            elif child not in colour:
                colour[child] = 1
                stack.append((child, iter(successors.get(child, ()))))
    return False
