"""The execution net: the pattern as the runtime fires it and the analysis explores it.

Each task t becomes `start:t` (consumes t's input places, marks `running:t`)
and `complete:t` (consumes `running:t`, marks t's output places); a silent
transition stays one transition that fires at once. The constraints become
extra places (pattern-format.md, "Execution semantics"):

- time (a, b): `complete:a` puts a token in `time:a>b`, each `start:b` takes one,
  so every start of b needs an earlier completion of a.
- func (a, b), supporter s and supported d: `start:s` marks `func-start:s>d`,
  which `start:d` takes (d starts only while s runs); `complete:d` marks
  `func-done:d>s`, which `complete:s` takes (s completes only after d has).
- space (a, b): no place; the order is free and the runtime interrupts the
  cobot while both run.

A process with `"completion": "implicit"` has its places (its tasks' `running:`
places too) in the net's `implicit`: it has completed once its tokens all lie
in its sink place, however many (BPMN: each end event consumes its token).

A silent transition with `cancels` resets what it names when it fires: a
place is emptied, a task's `running:t` too (the task is cancelled), and with
it the func constraint places that stand for that run of t: `func-start:t>d`
(t runs, so d may start) and `func-done:d>t` (d completed, for t to complete).

Call it only on a pattern whose rules hold (`rules.check_rules` found nothing
structural): it assumes every arc, performer and constraint end exists.
"""

from collections import defaultdict
from collections.abc import Callable
from dataclasses import dataclass
from typing import Literal

from hrc.engine.model import Constraint, Pattern, Process, Transition
from hrc.engine.petri import Marking, Net, NetTransition
from hrc.engine.taskconfig import ConfigError, cancels_of

Arcs = dict[str, list[tuple[str, int]]]


@dataclass(frozen=True)
class Firing:
    """A possible step in a marking and the marking after it."""

    transition: NetTransition
    marking: Marking


def supporter_of(pattern: Pattern, constraint: Constraint) -> tuple[str, str]:
    """(supporter, supported) of a func constraint: the cobot's task where exactly one is a cobot's, else t_a."""
    kinds = []
    for task_id in (constraint.source, constraint.target):
        task = pattern.transition(task_id)
        actor = pattern.actor(task.performer) if task and task.performer else None
        kinds.append(actor.type if actor else None)
    if kinds == ["operator", "cobot"]:
        return constraint.target, constraint.source
    return constraint.source, constraint.target


@dataclass(frozen=True)
class ConstraintPlace:
    """A place a constraint adds, and what it means in the pattern's words."""

    kind: Literal["time", "func-start", "func-done"]
    first: str
    """time: t_a; func-start: the supporter; func-done: the supported task."""
    second: str
    """time: t_b; func-start: the supported task; func-done: the supporter."""
    producer: str
    consumer: str

    def needed(self, name: Callable[[str], str] = str) -> str:
        """What the consumer waits for, as a person says it; `name` turns a task id into words."""
        first, second = name(self.first), name(self.second)
        if self.kind == "time":
            return f"a completion of {first} (time constraint {first} → {second})"
        if self.kind == "func-start":
            return f"{first} to be running (func constraint: {first} supports {second})"
        return f"{first} to complete (func constraint: {second} supports {first})"


def constraint_places(pattern: Pattern) -> dict[str, ConstraintPlace]:
    """Each constraint place by id, e.g. `time:a>b`, made by `complete:a` and taken by `start:b`."""
    places: dict[str, ConstraintPlace] = {}
    for constraint in pattern.constraints:
        a, b = constraint.source, constraint.target
        if constraint.type == "time":
            places[f"time:{a}>{b}"] = ConstraintPlace("time", a, b, f"complete:{a}", f"start:{b}")
        elif constraint.type == "func":
            s, d = supporter_of(pattern, constraint)
            places[f"func-start:{s}>{d}"] = ConstraintPlace(
                "func-start", s, d, f"start:{s}", f"start:{d}"
            )
            places[f"func-done:{d}>{s}"] = ConstraintPlace(
                "func-done", d, s, f"complete:{d}", f"complete:{s}"
            )
    return places


def build_execution_net(pattern: Pattern) -> Net:
    """The execution net of a structurally valid pattern, with initial and final marking."""
    pre: Arcs = defaultdict(list)
    post: Arcs = defaultdict(list)
    places: list[str] = []
    transitions: list[tuple[str, str, str]] = []  # (id, task, kind)
    resets: dict[str, tuple[str, ...]] = {}
    initial: dict[str, int] = {}
    final: dict[str, int] = {}
    implicit: list[str] = []
    for process in pattern.processes:
        places.extend(p.id for p in process.places)
        if process.completes_implicitly:
            implicit.extend(p.id for p in process.places)
            implicit.extend(f"running:{t.id}" for t in process.transitions if t.is_task)
        initial.update(process.initial_marking())
        for sink in process.sink_places():
            final[sink] = final.get(sink, 0) + 1
        inputs: Arcs = defaultdict(list)
        outputs: Arcs = defaultdict(list)
        transition_ids = {t.id for t in process.transitions}
        for source, target in process.arcs:
            if target in transition_ids:
                inputs[target].append((source, 1))
            else:
                outputs[source].append((target, 1))
        for transition in process.transitions:
            t = transition.id
            if not transition.is_task:
                transitions.append((t, t, "silent"))
                pre[t], post[t] = inputs[t], outputs[t]
                resets[t] = _resets(process, transition)
                continue
            running = f"running:{t}"
            places.append(running)
            transitions += [(f"start:{t}", t, "start"), (f"complete:{t}", t, "complete")]
            pre[f"start:{t}"] = list(inputs[t])
            post[f"start:{t}"] = [(running, 1)]
            pre[f"complete:{t}"] = [(running, 1)]
            post[f"complete:{t}"] = list(outputs[t])
    ignored = constraint_places(pattern)
    run_of: dict[str, list[str]] = defaultdict(list)  # task -> func places of its current run
    for place, constraint in ignored.items():
        places.append(place)
        post[constraint.producer].append((place, 1))
        pre[constraint.consumer].append((place, 1))
        if constraint.kind != "time":
            supporter = constraint.first if constraint.kind == "func-start" else constraint.second
            run_of[f"running:{supporter}"].append(place)
    for t, emptied in resets.items():
        resets[t] = tuple(p for place in emptied for p in (place, *run_of.get(place, ())))
    return Net(
        places=tuple(dict.fromkeys(places)),
        transitions=tuple(
            NetTransition(
                tid,
                task,
                kind,  # type: ignore[arg-type]
                tuple(_merged(pre[tid])),
                tuple(_merged(post[tid])),
                resets.get(tid, ()),
            )
            for tid, task, kind in transitions
        ),
        initial=Marking(initial),
        final=Marking(final),
        ignored=frozenset(ignored),
        implicit=frozenset(implicit),
    )


def _resets(process: Process, transition: Transition) -> tuple[str, ...]:
    """The places a silent transition's `cancels` empties: places as named, a task's `running:`.

    A malformed `cancels` is a task-config error of the check, which still
    decides soundness; the net then has no reset there, as without the key."""
    try:
        cancelled = cancels_of(process, transition)
    except ConfigError:
        return ()
    places = {p.id for p in process.places}
    tasks = {t.id for t in process.transitions if t.is_task}
    return tuple(
        node if node in places else f"running:{node}"
        for node in cancelled
        if node in places or node in tasks
    )


def possible_firings(net: Net, marking: Marking) -> list[Firing]:
    """Every start, completion and silent firing possible in `marking`, with the marking after each.

    This is the firing rule the runtime uses: a work item can be offered for
    each `start`, a running task can be completed by each `complete`, and a
    silent firing happens at once.
    """
    return [Firing(t, t.fire(marking)) for t in net.enabled(marking)]


def _merged(arcs: list[tuple[str, int]]) -> list[tuple[str, int]]:
    """Adds up parallel arcs to the same place. A model checked now has none (constraint-duplicate
    refuses a constraint written twice), but a version published before that rule keeps running."""
    weights: dict[str, int] = {}
    for place, weight in arcs:
        weights[place] = weights.get(place, 0) + weight
    return list(weights.items())
