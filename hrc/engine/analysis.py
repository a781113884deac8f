"""Soundness of an execution net: deadlocks, proper completion, dead tasks, boundedness.

The net is first reduced (`reduction.reduce_net`), then its reachable
markings are explored breadth first, so the first marking found with a
fault is one at the end of a shortest firing sequence, and that sequence,
expanded back into the original firings, is the witness shown to the
engineer (shortest up to the steps the reduction takes at once: a chain of
firings that nothing can interrupt is shown whole).

A process that completes implicitly (`Net.implicit`) has finished with any
number of tokens in its sink place and no other; its sink's tokens are
counted up to one (`_Explorer._counted`), and its tokens elsewhere while the
ends are marked mean it still runs, not that it ended improperly.

Reset arcs (`cancels`) are honoured, and they weaken one argument: a marking
that covers an ancestor proves a place unbounded only if no firing on the way
between them empties that place, since repeating the way would empty it again.

Exploration stops at the budget's `max_markings` or its deadline (see
`budget`), and so do the phases after it that walk every marking; whatever
was found by then is reported, and a verdict that needs the whole space
becomes "too large to decide" instead of a hang.
"""

import gc
from collections import Counter, deque
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Literal

from hrc.engine.budget import NO_TIME_LIMIT, Budget, Deadline
from hrc.engine.petri import Marking, Net
from hrc.engine.reduction import ReducedNet, reduce_net

FaultKind = Literal["deadlock", "livelock", "improper", "dead", "unbounded"]
Limit = Literal["markings", "time"]

# Phases that walk every marking look at the clock this often (a clock read
# costs about as much as looking at one marking).
_CLOCK_EVERY = 1024

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
    """False when the budget ran out before every fault kind could be ruled out."""
    faults: tuple[Fault, ...]
    stats: dict[str, int]
    """Sizes of the net, of the reduced net, and `markings`: how many were explored."""
    stopped_by: Limit | None = None
    """Which limit of the budget left the verdict undecided; None when decided."""

    @property
    def sound(self) -> bool | None:
        if self.faults:
            return False
        return True if self.decided else None


class _Explorer:
    """Breadth-first exploration of a reduced net.

    A marking is held as the sorted tuple of its tokens' place indices (a
    multiset): markings of workflow nets hold a handful of tokens among many
    places, so this is smaller and faster to hash than one count per place.
    Markings are numbered in the order they are found; edges and parents
    refer to those numbers.
    """

    def __init__(
        self, net: Net, reduced: ReducedNet, max_markings: int, deadline: Deadline
    ) -> None:
        self.net = net
        self.reduced = reduced
        self.max_markings = max_markings
        self.deadline = deadline
        self.stopped_by: Limit | None = None
        self.index = {place: i for i, place in enumerate(reduced.places)}
        self.pre = [self._tokens(t.pre) for t in reduced.transitions]
        self.post = [self._tokens(t.post) for t in reduced.transitions]
        self.resets = [frozenset(self.index[p] for p in t.resets) for t in reduced.transitions]
        self.need = [Counter(pre) for pre in self.pre]
        # Candidates per marked place, so a marking only tests transitions it can feed.
        self.consumers: list[list[int]] = [[] for _ in reduced.places]
        self.always = [t for t, pre in enumerate(self.pre) if not pre]
        for t, pre in enumerate(self.pre):
            if pre:
                self.consumers[pre[0]].append(t)
        self.ignored = {self.index[p] for p in net.ignored if p in self.index}
        self.implicit = {self.index[p] for p in net.implicit if p in self.index}
        self.open_ends = {self.index[p] for p in net.open_ends}
        self.final = self._state(net.final)
        # Only a firing that marks an open end can put a second token there.
        self.ends = [not self.open_ends.isdisjoint(post) for post in self.post]
        self.final_counts = Counter(self.final)
        self.cyclic = _has_cycle(reduced)
        self.ids: dict[_State, int] = {}
        self.order: list[_State] = []
        self.parent: list[tuple[int, int] | None] = []
        self.edges: list[list[tuple[int, int]]] = []
        self.unbounded: Fault | None = None
        self.expanded = 0
        """How many markings, in order, had their successors computed."""

    def _tokens(self, arcs: tuple[tuple[str, int], ...]) -> tuple[int, ...]:
        return tuple(sorted(self.index[place] for place, weight in arcs for _ in range(weight)))

    def _state(self, marking: Marking) -> _State:
        tokens = sorted(self.index[p] for p, n in marking.items() for _ in range(n))
        return self._counted(tokens)

    def _counted(self, tokens: list[int]) -> _State:
        """The sorted tokens as a state, an open end's counted up to one: nothing takes a token
        from a sink, so more of them enable nothing more, and a loop that ends a branch on each
        round stays bounded, as in BPMN, where the end event consumes the token."""
        if not self.open_ends:
            return tuple(tokens)
        kept: list[int] = []
        for i in tokens:
            if not (kept and kept[-1] == i and i in self.open_ends):
                kept.append(i)
        return tuple(kept)

    def marking(self, state: _State) -> Marking:
        return Marking((self.reduced.places[i], n) for i, n in Counter(state).items())

    def successors(self, state: _State) -> Iterator[tuple[int, _State]]:
        counts = Counter(state)
        candidates = set(self.always)
        for i in counts:
            candidates.update(self.consumers[i])
        for t in sorted(candidates):
            if all(counts[i] >= w for i, w in self.need[t].items()):
                tokens = list(state)
                for i in self.pre[t]:
                    tokens.remove(i)
                if self.resets[t]:
                    tokens = [i for i in tokens if i not in self.resets[t]]
                tokens.extend(self.post[t])
                tokens.sort()
                yield t, self._counted(tokens) if self.ends[t] else tuple(tokens)

    def _add(self, state: _State, parent: tuple[int, int] | None) -> int:
        number = self.ids[state] = len(self.order)
        self.order.append(state)
        self.parent.append(parent)
        self.edges.append([])
        return number

    def explore(self) -> bool:
        """Fills `order`, `parent` and `edges`; False when the budget stopped it early.

        The clock is read once per marking expanded: the cover test of a
        cyclic net walks every ancestor, so one expansion can cost far more
        than `_CLOCK_EVERY` plain markings.
        """
        queue = deque([self._add(self._state(self.net.initial), None)])
        while queue:
            number = queue.popleft()
            if self.deadline.passed():
                return self._stop("time", expanded=number)
            out = self.edges[number]
            for t, successor in self.successors(self.order[number]):
                known = self.ids.get(successor)
                if known is not None:
                    out.append((t, known))
                    continue
                found = self._add(successor, (number, t))
                out.append((t, found))
                if self.cyclic:
                    self.unbounded = self._covering(found)
                    if self.unbounded is not None:
                        return True  # An unbounded space has no end: what else it holds is moot.
                if len(self.order) >= self.max_markings:
                    return self._stop("markings", expanded=number + 1)
                queue.append(found)
        self.expanded = len(self.order)
        return True

    def _stop(self, limit: Limit, expanded: int) -> bool:
        self.stopped_by = limit
        self.expanded = expanded
        return False

    def out_of_time(self, step: int) -> bool:
        """For the phases after exploration: whether the deadline has passed, looked at every so often."""
        if step % _CLOCK_EVERY or not self.deadline.passed():
            return False
        self.stopped_by = "time"
        return True

    def _covering(self, number: int) -> Fault | None:
        """An ancestor this marking strictly covers proves a place unbounded (Karp–Miller),
        when a place that grew is emptied by no reset on the way from the ancestor, and is no
        open end, whose tokens are counted up to one."""
        state = self.order[number]
        counts = Counter(state)
        emptied: set[int] = set()
        link = self.parent[number]
        while link is not None:
            ancestor, t = link
            emptied |= self.resets[t]
            # Fewer tokens first: it is cheap and rules out most ancestors of a bounded net.
            fewer = len(self.order[ancestor]) < len(state)
            if fewer and (smaller := Counter(self.order[ancestor])) <= counts:
                grown = [
                    i
                    for i in counts
                    if counts[i] > smaller[i] and i not in emptied and i not in self.open_ends
                ]
                if grown:
                    prefix = self.path(ancestor)
                    return Fault(
                        "unbounded",
                        self.marking(state),
                        witness=prefix,
                        place=self.reduced.places[grown[0]],
                        repeat=self.path(number)[len(prefix) :],
                    )
            link = self.parent[ancestor]
        return None

    def path(self, number: int) -> tuple[str, ...]:
        """The original firings of the breadth-first (shortest) path to marking `number`."""
        steps: list[int] = []
        link = self.parent[number]
        while link is not None:
            number, t = link
            steps.append(t)
            link = self.parent[number]
        return tuple(f for t in reversed(steps) for f in self.reduced.transitions[t].firings)

    def is_final(self, state: _State) -> bool:
        return tuple(i for i in state if i not in self.ignored) == self.final

    def is_improper(self, state: _State) -> bool:
        """The end is marked but something else (apart from constraint places) still is too,
        a token of a process that completes implicitly aside: that process still runs."""
        counts = Counter(state)
        if not self.final_counts <= counts:
            return False
        left = counts - self.final_counts
        return any(i not in self.ignored and i not in self.implicit for i in left)

    def fault(self, kind: FaultKind, number: int) -> Fault:
        return Fault(kind, self.marking(self.order[number]), self.path(number))


def analyse(net: Net, budget: Budget = NO_TIME_LIMIT, deadline: Deadline | None = None) -> Analysis:
    """Decides soundness and boundedness of an execution net within `budget`; see the module docstring.

    `deadline` is the one of a larger check that already started; by default
    the budget's time starts now.
    """
    with _no_cycle_collection():
        return _explored(net, budget.max_markings, deadline or budget.start())


def _explored(net: Net, max_markings: int, deadline: Deadline) -> Analysis:
    reduced = reduce_net(net)
    explorer = _Explorer(net, reduced, max_markings, deadline)
    explorer.explore()
    faults: list[Fault] = []
    if explorer.unbounded is not None:
        faults.append(explorer.unbounded)
    else:
        faults.extend(_local_faults(explorer))
        if explorer.stopped_by is None:
            faults.extend(_global_faults(explorer))
    stats = {
        "net_places": len(net.places),
        "net_transitions": len(net.transitions),
        "reduced_places": len(reduced.places),
        "reduced_transitions": len(reduced.transitions),
        "markings": len(explorer.order),
    }
    decided = explorer.stopped_by is None
    return Analysis(decided, tuple(faults), stats, explorer.stopped_by)


@contextmanager
def _no_cycle_collection() -> Iterator[None]:
    """Python's cycle collector paused while the space is walked and freed. Its markings and
    edges are millions of objects without cycles (refcounting frees them), yet each full
    collection walks them all: a third of the time of a large space, in pauses of a tenth of a
    second that no clock read can cut short, so a check ran on well past its deadline. They are
    freed before the collector resumes, or its first collection would walk them all again."""
    paused = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if paused:
            gc.enable()


def _local_faults(explorer: _Explorer) -> Iterator[Fault]:
    """Faults one marking shows: the first deadlock and the first improper end, in BFS order.

    Only expanded markings count: past the cap, "no successor" would be a lie.
    Past the deadline, the first faults among the markings looked at so far.
    """
    deadlock = improper = None
    for number in range(explorer.expanded):
        if explorer.out_of_time(number):
            break
        state = explorer.order[number]
        if explorer.is_improper(state):
            improper = number if improper is None else improper
        elif deadlock is None and not explorer.edges[number] and not explorer.is_final(state):
            deadlock = number
    if deadlock is not None:
        yield explorer.fault("deadlock", deadlock)
    if improper is not None:
        yield explorer.fault("improper", improper)


def _global_faults(explorer: _Explorer) -> Iterator[Fault]:
    """Faults that need the whole space: no way to the end (livelock), transitions that never fire.

    Nothing when the deadline passes first (`explorer.stopped_by` says so): a
    livelock or a dead transition found in part of the space is no finding.
    Each walk over the space reads the clock as the exploration's phases do.
    """
    reverse: list[list[int]] = [[] for _ in explorer.order]
    finals: list[int] = []
    dead_ends: list[int] = []
    fired: set[int] = set()
    for number, out in enumerate(explorer.edges):
        if explorer.out_of_time(number):
            return
        for t, successor in out:
            reverse[successor].append(number)
            fired.add(t)
        if explorer.is_final(explorer.order[number]):
            finals.append(number)
        if not out:
            dead_ends.append(number)
    can_finish = _backwards(explorer, finals, reverse)
    can_end = _backwards(explorer, dead_ends, reverse) if can_finish is not None else None
    if can_finish is None or can_end is None:
        return
    # A livelock: the case runs on but can neither finish nor even get stuck.
    looping = next(
        (n for n in range(len(explorer.order)) if n not in can_finish and n not in can_end), None
    )
    if looping is not None:
        yield explorer.fault("livelock", looping)
    firings = {firing for t in fired for firing in explorer.reduced.transitions[t].firings}
    for transition in explorer.net.transitions:
        if transition.id not in firings:
            yield Fault("dead", None, transition=transition.id)


def _backwards(explorer: _Explorer, starts: list[int], reverse: list[list[int]]) -> set[int] | None:
    """The markings from which one of `starts` is reachable; None when the deadline passed."""
    reached = set(starts)
    queue = deque(starts)
    step = 0
    while queue:
        step += 1
        if explorer.out_of_time(step):
            return None
        for predecessor in reverse[queue.popleft()]:
            if predecessor not in reached:
                reached.add(predecessor)
                queue.append(predecessor)
    return reached


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
