"""The rules of the formal model (thesis 4.2), each reported with its code and element ids.

`check_rules` assumes the document's shape is right (document.read_pattern
succeeded) and reports every broken rule it finds, so an engineer sees all
of them at once instead of one per save.
"""

from collections import Counter, defaultdict
from collections.abc import Iterable

from hrc.engine.graph import reachable
from hrc.engine.issues import STRUCTURAL_CODES, Issue, error
from hrc.engine.model import CONSTRAINT_TYPES, Pattern, Process

__all__ = ["STRUCTURAL_CODES", "check_rules"]


def check_rules(pattern: Pattern) -> list[Issue]:
    """Every broken structural rule of the 7-tuple, in the order of pattern-format.md."""
    return [
        *_duplicate_ids(pattern),
        *_arcs(pattern),
        *_actors(pattern),
        *_constraints(pattern),
        *(issue for process in pattern.processes for issue in _workflow_net(process)),
    ]


def _duplicate_ids(pattern: Pattern) -> Iterable[Issue]:
    kinds: dict[str, list[str]] = defaultdict(list)
    for actor in pattern.actors:
        kinds[actor.id].append("actor")
    for process in pattern.processes:
        kinds[process.id].append("process")
        for place in process.places:
            kinds[place.id].append(f"place of {process.id}")
        for transition in process.transitions:
            kinds[transition.id].append(f"transition of {process.id}")
    for element_id, uses in kinds.items():
        if len(uses) > 1:
            yield error(
                "duplicate-id",
                f"The id {element_id!r} is used {len(uses)} times ({', '.join(uses)}); "
                "ids must be unique across the whole document: rename all but one.",
                element_id,
            )


def _arcs(pattern: Pattern) -> Iterable[Issue]:
    for process in pattern.processes:
        places = {p.id for p in process.places}
        transitions = {t.id for t in process.transitions}
        for source, target in process.arcs:
            unknown = [end for end in (source, target) if end not in places | transitions]
            for end in unknown:
                owner = pattern.process_of(end)
                where = f"it belongs to process {owner.id}" if owner else "it does not exist"
                yield error(
                    "unknown-node",
                    f"The arc {source} → {target} in process {process.id} names {end!r}, "
                    f"but {where}: an arc joins nodes of its own net.",
                    source,
                    target,
                )
            if unknown:
                continue
            if (source in places) == (target in places):
                kind = "places" if source in places else "transitions"
                yield error(
                    "arc-kind",
                    f"The arc {source} → {target} joins two {kind}; an arc must join a place "
                    "and a transition (put a transition or a place between them).",
                    source,
                    target,
                )


def _actors(pattern: Pattern) -> Iterable[Issue]:
    known = {actor.id for actor in pattern.actors}
    assigned: set[str] = set()
    for process in pattern.processes:
        for actor_id in process.actors:
            if actor_id not in known:
                yield error(
                    "unknown-actor",
                    f"Process {process.id} is assigned the actor {actor_id!r}, which is not "
                    "declared under actors.",
                    process.id,
                    actor_id,
                )
        assigned.update(process.actors)
        performing = {t.performer for t in process.transitions if t.performer is not None}
        for transition in process.transitions:
            performer = transition.performer
            if performer is not None and performer not in process.actors:
                reason = "not assigned to" if performer in known else "not an actor of"
                yield error(
                    "unknown-actor",
                    f"Task {transition.id} is performed by {performer!r}, which is {reason} "
                    f"process {process.id}: assign the actor to the process or pick another "
                    "performer.",
                    transition.id,
                    performer,
                )
        for actor_id in process.actors:
            if actor_id in known and actor_id not in performing:
                yield error(
                    "idle-actor",
                    f"Actor {actor_id} is assigned to process {process.id} but performs none of "
                    "its tasks: give it a task there or remove it from the process.",
                    actor_id,
                    process.id,
                )
    for actor in pattern.actors:
        if actor.id not in assigned:
            yield error(
                "unassigned-actor",
                f"Actor {actor.id} is assigned to no process: add it to a process' actors or "
                "remove it.",
                actor.id,
            )


def _constraints(pattern: Pattern) -> Iterable[Issue]:
    for constraint in pattern.constraints:
        a, b = constraint.source, constraint.target
        name = f"The {constraint.type} constraint {a} → {b}"
        if constraint.type not in CONSTRAINT_TYPES:
            yield error(
                "constraint-type",
                f"The constraint {a} → {b} has type {constraint.type!r}; the type must be one of "
                f"{', '.join(CONSTRAINT_TYPES)}.",
                a,
                b,
            )
        ends = [pattern.transition(a), pattern.transition(b)]
        missing = [end for end, found in zip((a, b), ends, strict=True) if found is None]
        for end in missing:
            what = "a place" if pattern.process_of(end) else "no element"
            yield error(
                "unknown-node",
                f"{name} names {end!r}, which is {what}; a constraint joins two tasks.",
                a,
                b,
            )
        if a == b:
            yield error("constraint-self", f"{name} joins a task to itself; remove it.", a)
            continue
        task_a, task_b = ends
        if task_a is None or task_b is None:
            continue
        unperformed = [t.id for t in (task_a, task_b) if t.performer is None]
        if unperformed:
            yield error(
                "constraint-unperformed",
                f"{name} joins {' and '.join(unperformed)}, which no actor performs; "
                "constraints join tasks of actors, not splits or joins.",
                *unperformed,
            )
        elif task_a.performer == task_b.performer:
            yield error(
                "constraint-same-performer",
                f"{name} joins two tasks of the same performer ({task_a.performer}); "
                "constraints relate tasks of different actors (order one actor's tasks with arcs).",
                a,
                b,
            )


def _workflow_net(process: Process) -> Iterable[Issue]:
    """A workflow net has one source place, one sink place, and every node on a path between."""
    sources, sinks = process.source_places(), process.sink_places()
    if len(sources) != 1 or len(sinks) != 1:
        parts = []
        if len(sources) != 1:
            parts.append(f"{len(sources)} source places ({_listed(sources)})")
        if len(sinks) != 1:
            parts.append(f"{len(sinks)} sink places ({_listed(sinks)})")
        yield error(
            "not-workflow-net",
            f"Process {process.id} has {' and '.join(parts)}; a workflow net has exactly one "
            "place where a case starts (no incoming arc) and one where it ends (no outgoing arc).",
            process.id,
            *sources,
            *sinks,
        )
        return
    successors: dict[str, list[str]] = defaultdict(list)
    predecessors: dict[str, list[str]] = defaultdict(list)
    for source, target in process.arcs:
        successors[source].append(target)
        predecessors[target].append(source)
    forward = reachable([sources[0]], successors)
    backward = reachable([sinks[0]], predecessors)
    nodes = [p.id for p in process.places] + [t.id for t in process.transitions]
    counts = Counter(nodes)
    stray = [
        node for node in nodes if counts[node] == 1 and not (node in forward and node in backward)
    ]
    if stray:
        yield error(
            "not-workflow-net",
            f"In process {process.id}, {_listed(stray)} "
            f"{'lies' if len(stray) == 1 else 'lie'} on no path from {sources[0]} to {sinks[0]}: "
            "connect them or remove them.",
            process.id,
            *stray,
        )


def _listed(ids: list[str], limit: int = 8) -> str:
    if not ids:
        return "none"
    shown = ", ".join(ids[:limit])
    return shown if len(ids) <= limit else f"{shown} and {len(ids) - limit} more"
