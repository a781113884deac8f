"""A plain exhaustive reachability search: the yardstick the engine's reduced search must agree with.

Deliberately naive and independent of `hrc.engine.analysis`: no reduction,
the whole execution net, the textbook definition of soundness (van der
Aalst) with constraint places set aside for proper completion, and the
Karp–Miller ancestor cover test for unboundedness: with reset arcs, a place
that grew proves it only when no firing on the way from the ancestor resets it.
"""

from collections import deque

from hrc.engine.petri import Marking, Net, NetTransition


def plain_soundness(net: Net, limit: int = 100_000) -> bool:
    """True when sound and bounded; raises RuntimeError past `limit` markings."""
    start = net.initial
    parents: dict[Marking, tuple[Marking, NetTransition] | None] = {start: None}
    successors: dict[Marking, list[Marking]] = {}
    fired: set[str] = set()
    queue = deque([start])
    while queue:
        marking = queue.popleft()
        successors[marking] = []
        for transition in net.transitions:
            if not transition.is_enabled(marking):
                continue
            after = transition.fire(marking)
            fired.add(transition.id)
            successors[marking].append(after)
            if after in parents:
                continue
            parents[after] = (marking, transition)
            if _covers_an_ancestor(after, parents):
                return False
            if len(parents) > limit:
                raise RuntimeError("state space over the limit")
            queue.append(after)
    if any(_ends_improperly(net, m) for m in parents):
        return False
    if fired != {t.id for t in net.transitions}:
        return False
    can_finish = {m for m in parents if net.is_final(m)}
    changed = True
    while changed:
        changed = False
        for marking, nexts in successors.items():
            if marking not in can_finish and any(n in can_finish for n in nexts):
                can_finish.add(marking)
                changed = True
    return len(can_finish) == len(parents)


def _covers_an_ancestor(
    marking: Marking, parents: dict[Marking, tuple[Marking, NetTransition] | None]
) -> bool:
    emptied: set[str] = set()
    link = parents[marking]
    while link is not None:
        ancestor, transition = link
        emptied.update(transition.resets)
        covers = all(marking.get(p) >= n for p, n in ancestor.items())
        if covers and any(marking[p] > ancestor.get(p) and p not in emptied for p in marking):
            return True
        link = parents[ancestor]
    return False


def _ends_improperly(net: Net, marking: Marking) -> bool:
    covers = all(marking.get(p) >= n for p, n in net.final.items())
    return covers and not net.is_final(marking)
