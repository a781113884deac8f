"""The rules of the formal model (thesis 4.2), each reported with its code and element ids.

`check_rules` assumes the document's shape is right (document.read_pattern
succeeded) and reports every broken rule it finds, so an engineer sees all
of them at once instead of one per save. Besides the 7-tuple's rules it
reports each `rewrite` note (`to-rewrite`), which leaves the net well formed.
"""

from collections import Counter, defaultdict
from collections.abc import Iterable

from hrc.engine.graph import reachable
from hrc.engine.issues import STRUCTURAL_CODES, Issue, error
from hrc.engine.model import COMPLETIONS, CONSTRAINT_TYPES, Pattern, Process
from hrc.engine.wording import Names, sentence

__all__ = ["STRUCTURAL_CODES", "check_rules"]


def check_rules(pattern: Pattern) -> list[Issue]:
    """Every broken structural rule of the 7-tuple, in the order of pattern-format.md, then
    every element still to rewrite."""
    names = Names(pattern)
    return [
        *_duplicate_ids(pattern, names),
        *_arcs(pattern, names),
        *_actors(pattern, names),
        *_constraints(pattern, names),
        *_constraint_pairs(pattern, names),
        *_no_actors(pattern, names),
        *_workpieces(pattern, names),
        *(issue for process in pattern.processes for issue in _workflow_net(process, names)),
        *_completions(pattern, names),
        *_to_rewrite(pattern, names),
    ]


def _duplicate_ids(pattern: Pattern, names: Names) -> Iterable[Issue]:
    kinds: dict[str, list[str]] = defaultdict(list)
    for actor in pattern.actors:
        kinds[actor.id].append(f"the {actor.type}'s lane")
    for process in pattern.processes:
        kinds[process.id].append("a process")
        for place in process.places:
            kinds[place.id].append("a place")
        for transition in process.transitions:
            kinds[transition.id].append("a task" if transition.is_task else "a split/join")
    for element_id, uses in kinds.items():
        if len(uses) > 1:
            yield error(
                "duplicate-id",
                f"The id {element_id!r} is given to {len(uses)} elements ({', '.join(uses)}); "
                "each element needs its own id: rename all but one in the properties panel.",
                element_id,
            )


def _arcs(pattern: Pattern, names: Names) -> Iterable[Issue]:
    for process in pattern.processes:
        places = {p.id for p in process.places}
        nodes = places | {t.id for t in process.transitions}
        for source, target in process.arcs:
            unknown = [end for end in (source, target) if end not in nodes]
            for end in unknown:
                owner = pattern.process_of(end)
                where = f"it belongs to process {owner.id}" if owner else "no such element exists"
                yield error(
                    "unknown-node",
                    f"An arrow in {names.process(process.id)} leads "
                    f"{'from' if end == source else 'to'} {end!r}, but {where}: an arrow joins "
                    "elements of its own process. Delete the arrow and draw it again.",
                    source,
                    target,
                )
            if unknown:
                continue
            if (source in places) == (target in places):
                fix = (
                    "put a task or a split/join between them"
                    if source in places
                    else "put a place between them"
                )
                yield error(
                    "arc-kind",
                    f"The arrow from {names.node(source)} to {names.node(target)} joins two "
                    f"{'places' if source in places else 'tasks'}: an arrow goes from a place to "
                    f"a task or from a task to a place, so {fix}.",
                    source,
                    target,
                )


def _actors(pattern: Pattern, names: Names) -> Iterable[Issue]:
    known = {actor.id for actor in pattern.actors}
    assigned: set[str] = set()
    for process in pattern.processes:
        for actor_id in process.actors:
            if actor_id not in known:
                yield error(
                    "unknown-actor",
                    f"{sentence(names.process(process.id))} has a lane for {actor_id!r}, "
                    "which is not one of the pattern's actors: add the actor or remove the lane.",
                    process.id,
                    actor_id,
                )
        assigned.update(process.actors)
        performing = {t.performer for t in process.transitions if t.performer is not None}
        for transition in process.transitions:
            performer = transition.performer
            if performer is not None and performer not in process.actors:
                reason = (
                    f"has no lane in {names.process(process.id)}"
                    if performer in known
                    else "is not one of the pattern's actors"
                )
                yield error(
                    "unknown-actor",
                    f"{sentence(names.task(transition.id))} is "
                    f"performed by {performer!r}, which {reason}: move the task into an actor's "
                    "lane or pick another performer.",
                    transition.id,
                    performer,
                )
        for actor_id in process.actors:
            if actor_id in known and actor_id not in performing:
                yield error(
                    "idle-actor",
                    f"The lane of {names.actor(actor_id)} in {names.process(process.id)} has no "
                    "task: draw a task in it or remove the lane.",
                    actor_id,
                    process.id,
                )
    for actor in pattern.actors:
        if actor.id not in assigned:
            yield error(
                "unassigned-actor",
                f"{sentence(names.actor(actor.id))} has no lane: add a lane for it or "
                "remove the actor.",
                actor.id,
            )


def _constraints(pattern: Pattern, names: Names) -> Iterable[Issue]:
    for constraint in pattern.constraints:
        a, b = constraint.source, constraint.target
        pair = f"{names.name(a)} → {names.name(b)}"
        name = f"The {constraint.type} constraint {pair}"
        if constraint.type not in CONSTRAINT_TYPES:
            yield error(
                "constraint-type",
                f"The constraint {pair} has type {constraint.type!r}; the type must be one of "
                f"{', '.join(CONSTRAINT_TYPES)}.",
                a,
                b,
            )
        ends = [pattern.transition(a), pattern.transition(b)]
        missing = [end for end, found in zip((a, b), ends, strict=True) if found is None]
        for end in missing:
            what = names.place(end) if pattern.process_of(end) else "no element of the drawing"
            yield error(
                "unknown-node",
                f"{name} ends at {end!r}, which is {what}: a constraint joins two tasks.",
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
                f"{name} ends at {names.nodes(unperformed)}, which no actor performs: "
                "constraints join tasks in actors' lanes, not splits or joins.",
                *unperformed,
            )
        elif task_a.performer == task_b.performer:
            yield error(
                "constraint-same-performer",
                f"{name} joins two tasks of the same {names.actor(task_a.performer or '')}: "
                "constraints relate tasks of different actors (order one actor's tasks with "
                "arrows).",
                a,
                b,
            )


def _constraint_pairs(pattern: Pattern, names: Names) -> Iterable[Issue]:
    """constr is a partial function T × T ⇀ {time, space, func}: one type per ordered pair."""
    written: dict[tuple[str, str], list[str]] = defaultdict(list)
    for constraint in pattern.constraints:
        if constraint.source != constraint.target and constraint.type in CONSTRAINT_TYPES:
            written[constraint.source, constraint.target].append(constraint.type)
    for (a, b), types in written.items():
        pair = f"{names.name(a)} → {names.name(b)}"
        for constraint_type, count in Counter(types).items():
            if count > 1:
                yield error(
                    "constraint-duplicate",
                    f"The {constraint_type} constraint {pair} is drawn {count} times: "
                    "a constraint is written once, so delete all but one.",
                    a,
                    b,
                )
        distinct = list(dict.fromkeys(types))
        if len(distinct) > 1:
            yield error(
                "constraint-conflict",
                f"The constraints {pair} give one pair of tasks {len(distinct)} types "
                f"({', '.join(distinct)}): an ordered pair of tasks has one constraint type, "
                "so keep the one you mean and delete the others.",
                a,
                b,
            )


def _no_actors(pattern: Pattern, names: Names) -> Iterable[Issue]:
    if not pattern.actors:
        yield error(
            "no-actors",
            "The pattern has no actors: add an operator or cobot lane to "
            f"{'the drawing' if len(pattern.processes) == 1 else 'each process'}.",
            *(process.id for process in pattern.processes),
        )
        return
    for process in pattern.processes:
        if not process.actors:
            yield error(
                "no-actors",
                f"{sentence(names.process(process.id))} has no actors: draw a lane for the "
                "operator or cobot who performs its tasks.",
                process.id,
            )


def _workpieces(pattern: Pattern, names: Names) -> Iterable[Issue]:
    for process in pattern.processes:
        if not (process.workpiece or "").strip():
            yield error(
                "unassigned-workpiece",
                f"{sentence(names.process(process.id))} works on no workpiece: every process "
                "works on one, so name it in the pattern's properties (select nothing, then "
                f"Workpiece of net {process.id}).",
                process.id,
            )


def _workflow_net(process: Process, names: Names) -> Iterable[Issue]:
    """A workflow net has one source place, one sink place, and every node on a path between.

    A process imported from BPMN (implicit completion) may also hold places nothing enters
    that are written with no token: BPMN never starts what waits there, so they are no start,
    and the analysis finds what follows them dead.
    """
    sources, sinks = process.source_places(), process.sink_places()
    unreached = [
        p.id
        for p in process.places
        if process.completes_implicitly and p.tokens == 0 and p.id in sources
    ]
    sources = [place for place in sources if place not in unreached]
    if len(sources) != 1 or len(sinks) != 1:
        parts = []
        if not sources:
            parts.append("no place where a case starts (every place has an arrow coming in)")
        elif len(sources) > 1:
            parts.append(
                f"{len(sources)} places where a case could start ({names.nodes(sources)}: "
                "no arrow comes into them)"
            )
        if not sinks:
            parts.append("no place where a case ends (every place has an arrow going out)")
        elif len(sinks) > 1:
            parts.append(
                f"{len(sinks)} places where a case could end ({names.nodes(sinks)}: "
                "no arrow leaves them)"
            )
        yield error(
            "not-workflow-net",
            f"{sentence(names.process(process.id))} has {' and '.join(parts)}. It needs "
            "exactly one place where a case starts and one where it ends: connect the loose "
            "places with arrows or remove them.",
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
    forward = reachable([sources[0], *unreached], successors)
    backward = reachable([sinks[0]], predecessors)
    nodes = [p.id for p in process.places] + [t.id for t in process.transitions]
    counts = Counter(nodes)
    stray = [
        node for node in nodes if counts[node] == 1 and not (node in forward and node in backward)
    ]
    if stray:
        yield error(
            "not-workflow-net",
            f"In {names.process(process.id)}, {names.nodes(stray)} "
            f"{'is' if len(stray) == 1 else 'are'} on no path from the start "
            f"({names.place(sources[0])}) to the end ({names.place(sinks[0])}): connect "
            f"{'it' if len(stray) == 1 else 'them'} with arrows or remove "
            f"{'it' if len(stray) == 1 else 'them'}.",
            process.id,
            *stray,
        )


def _completions(pattern: Pattern, names: Names) -> Iterable[Issue]:
    """`completion` says when a case of the process has completed; another value leaves it open."""
    for process in pattern.processes:
        given = process.extra.get("completion", "proper")
        if given not in COMPLETIONS:
            yield error(
                "format",
                f"{sentence(names.process(process.id))} has completion {given!r}: it is "
                '"proper" (one token in its end place, nothing else left; the default) or '
                '"implicit" (every token in its end place, however many: BPMN\'s rule).',
                process.id,
            )


def _to_rewrite(pattern: Pattern, names: Names) -> Iterable[Issue]:
    """A `rewrite` note marks what an importer could not say in hrc's terms (a condition in
    another expression language, a loop without a condition): the model cannot run as meant."""
    for process in pattern.processes:
        notes = [(p.id, p.extra) for p in process.places]
        notes += [(t.id, t.extra) for t in process.transitions]
        for node, extra in notes:
            if "rewrite" not in extra:
                continue
            note = extra["rewrite"]
            what = note.strip().rstrip(".") if isinstance(note, str) else ""
            yield error(
                "to-rewrite",
                f"{sentence(names.node(node))} needs rewriting"
                + (f": {what}. " if what else ". ")
                + "Rewrite it in hrc's terms, then remove its 'rewrite' key.",
                node,
            )
