"""Structural reduction of an execution net before its state space is explored.

Concurrency is what blows state spaces up: three parallel chains of n tasks
have about (2n)^3 markings, although nothing can go wrong between the tasks
of one chain. Post-agglomeration (Berthelot; Murata's fusion of series
transitions is a special case) removes that: where a place p is marked only
by some transitions h and emptied only by one transition t whose sole input
is p, t can never be disabled once p is marked and never competes for a
token, so firing t right after each h changes no verdict. Each h becomes "h
then t", p and t disappear, and a chain of tasks collapses into the
transition that starts it.

What is preserved (the arguments in `reduce_net`'s docstring): the reachable
markings of the reduced net are reachable markings of the original one (the
original's other markings only differ by tokens in removed places, each of
which can always move on), dead markings, reachability of the final marking
from every marking, proper completion, boundedness, and which transitions
can fire. Every reduced transition remembers the original firings it stands
for, so a witness found in the reduced net expands into a firing sequence of
the original.

A process that completes implicitly changes nothing here: its sink place is
part of the final marking, so it stays, and a token moved on early by t lies
in the same process, which has not completed while a token is in p either.

Reset arcs (`cancels`) are kept: a producer h keeps its resets, which happen
before t's tokens arrive as they would have. A reset region must take p and
t's outputs together or leave them all alone: then emptying the region
gives the same marking whether t fired already or not (a terminate that
empties its whole process keeps the process' chains reducible), while a
region with p in it and t's outputs outside would have t move tokens out of
its reach.
"""

from collections import defaultdict
from dataclasses import dataclass

from hrc.engine.petri import Net


@dataclass
class _Transition:
    pre: dict[str, int]
    post: dict[str, int]
    firings: list[str]
    resets: tuple[str, ...] = ()


@dataclass(frozen=True)
class ReducedTransition:
    pre: tuple[tuple[str, int], ...]
    post: tuple[tuple[str, int], ...]
    firings: tuple[str, ...]
    """The original transitions' ids, in an order in which they can fire."""
    resets: tuple[str, ...] = ()
    """The places it empties after taking `pre`, before putting `post`."""


@dataclass(frozen=True)
class ReducedNet:
    places: tuple[str, ...]
    transitions: tuple[ReducedTransition, ...]


def reduce_net(net: Net) -> ReducedNet:
    """Agglomerates every place p with producers H and one consumer t where •t = {p}.

    Conditions, each needed for the preservation argument: p is unmarked
    initially and not part of the final marking (so every token in it was
    put there by some h); p's only consumer is t and t's only input is p
    with weight 1 (so t is enabled exactly while p is marked and nobody else
    can take the token); t does not produce into p (no self-loop); t produces
    something (so tokens piling up in p still show as unboundedness).
    Under these, any firing sequence of the original can be reordered to fire
    t right after the h that marked p: firing t earlier only adds tokens
    sooner and takes none that another transition needed. With reset arcs,
    also: t resets nothing, and each transition's resets hold either p and
    every place t produces into, or none of them; so firing t earlier either
    commutes with a reset or is undone by it exactly.
    """
    transitions = {
        t.id: _Transition(dict(t.pre), dict(t.post), [t.id], t.resets) for t in net.transitions
    }
    regions = {frozenset(t.resets) for t in net.transitions if t.resets}
    producers: dict[str, set[str]] = defaultdict(set)
    consumers: dict[str, set[str]] = defaultdict(set)
    for tid, transition in transitions.items():
        for place in transition.pre:
            consumers[place].add(tid)
        for place in transition.post:
            producers[place].add(tid)
    protected = set(net.initial) | set(net.final)
    places = list(net.places)
    worklist = list(reversed(places))
    removed: set[str] = set()
    while worklist:
        place = worklist.pop()
        if place in removed or place in protected:
            continue
        if len(consumers[place]) != 1 or not producers[place]:
            continue
        (tid,) = consumers[place]
        consumer = transitions[tid]
        if consumer.pre != {place: 1} or place in consumer.post or not consumer.post:
            continue
        if consumer.resets or _split_by_a_region(regions, {place, *consumer.post}):
            continue
        if tid in producers[place]:
            continue
        for hid in producers[place]:
            producer = transitions[hid]
            times = producer.post.pop(place)
            for target, weight in consumer.post.items():
                producer.post[target] = producer.post.get(target, 0) + weight * times
                producers[target].add(hid)
            producer.firings.extend(consumer.firings * times)
        for target in consumer.post:
            producers[target].discard(tid)
            worklist.append(target)
        del transitions[tid]
        removed.add(place)
        producers.pop(place, None)
        consumers.pop(place, None)
    kept = tuple(p for p in places if p not in removed)
    return ReducedNet(
        places=kept,
        transitions=tuple(
            ReducedTransition(
                tuple(sorted(t.pre.items())),
                tuple(sorted(t.post.items())),
                tuple(t.firings),
                # A removed place is never marked in the reduced net: nothing to empty there.
                tuple(place for place in t.resets if place not in removed),
            )
            for t in transitions.values()
        ),
    )


def _split_by_a_region(regions: set[frozenset[str]], places: set[str]) -> bool:
    """Whether some reset region empties part of `places` but not all of them."""
    return any(not region.isdisjoint(places) and not places <= region for region in regions)
