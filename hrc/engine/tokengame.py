"""The execution net as plain JSON, for the editor's token game.

The net is `execution.build_execution_net`'s: the same one the analysis
explores and the runtime fires, so the game plays exactly the semantics the
check judged. `execution_net_json` describes it in words the editor can draw
on the pattern's own elements:

    {
      "places": [
        {"id": "p2", "label": "p2", "tokens": 0, "kind": "flow", "of": "p2"},
        {"id": "running:tc1", "label": "tc1 running", "tokens": 0, "kind": "busy", "of": "tc1"},
        {"id": "time:to1>tc2", "label": "to1 done, for tc2", "tokens": 0, "kind": "constraint",
         "of": ["to1", "tc2"], "constraint": {"index": 0, "type": "time", "role": "time"},
         "needs": "a completion of to1 (time constraint to1 → tc2)"}
      ],
      "transitions": [
        {"id": "start:tc1", "label": "start tc1", "kind": "start", "task": "tc1", "performer": "c"},
        {"id": "complete:tc1", "label": "complete tc1", "kind": "complete", "task": "tc1", "performer": "c"},
        {"id": "t1", "label": "t1", "kind": "silent", "task": "t1", "performer": null,
         "resets": ["p4", "running:tc1"]}
      ],
      "arcs": [["p2", "start:tc1"], ["start:tc1", "running:tc1"], ...],
      "initial": {"p1": 1},
      "final": {"p9": 1},
      "ignored": ["time:to1>tc2"],
      "open_ends": []
    }

- a `flow` place is a place of the pattern (`of`: its id); a `busy` place is
  marked while the task `of` runs; a `constraint` place is what a constraint
  adds (`of`: its two tasks, `from` and `to` as the document writes them;
  `constraint`: its index in the document's `constraints`, its type, and
  `role`: `time`, or `func-start` (the supporter runs) / `func-done` (the
  supported task has completed); `needs` says what the task that takes its
  token waits for);
- a transition is a task's `start` or `complete`, or a `silent` step of the
  pattern (`task`: the pattern transition it belongs to);
- a transition fires when each of its input places holds a token, taking one
  from each, emptying its `resets` places (a `cancels` key: `running:t`
  cancels task t), and putting one in each output place; silent steps fire
  at once, the game leaving a timer's wait out;
- the case ends properly in `final`, whatever the `ignored` (constraint)
  places hold; an `open_ends` place (the end of a process with
  `"completion": "implicit"`) may then hold more than its one token.
"""

from typing import Any

from hrc.engine.execution import ConstraintPlace, build_execution_net, constraint_places
from hrc.engine.model import Pattern

Json = dict[str, Any]


_ConstraintKey = tuple[str, tuple[str, str] | frozenset[str]]


def execution_net_json(pattern: Pattern) -> Json:
    """The execution net of a pattern whose structural rules hold (see execution.py)."""
    net = build_execution_net(pattern)
    performers = {t.id: t.performer for _, t in pattern.transitions()}
    constraints = constraint_places(pattern)
    # The first constraint behind each constraint place, found once rather than per place.
    index_of: dict[_ConstraintKey, int] = {}
    for i, c in enumerate(pattern.constraints):
        index_of.setdefault(_constraint_key(c.type, c.source, c.target), i)
    places = []
    for place in net.places:
        if place in constraints:
            described = _constraint_place(pattern, constraints[place], index_of)
        elif place.startswith("running:"):
            task = place.split(":", 1)[1]
            described = {"label": f"{task} running", "kind": "busy", "of": task}
        else:
            described = {"label": place, "kind": "flow", "of": place}
        label = described.pop("label")
        places.append({"id": place, "label": label, "tokens": net.initial.get(place), **described})
    transitions = [
        {
            "id": t.id,
            "label": t.label,
            "kind": t.kind,
            "task": t.task,
            "performer": performers.get(t.task),
            "resets": list(t.resets),
        }
        for t in net.transitions
    ]
    arcs: list[list[str]] = []
    for t in net.transitions:
        arcs += [[place, t.id] for place, _ in t.pre]
        arcs += [[t.id, place] for place, _ in t.post]
    return {
        "places": places,
        "transitions": transitions,
        "arcs": arcs,
        "initial": dict(net.initial),
        "final": dict(net.final),
        "ignored": sorted(net.ignored),
        "open_ends": sorted(net.open_ends),
    }


def _constraint_key(kind: str, source: str, target: str) -> _ConstraintKey:
    """A time constraint is known by its ordered ends, a func one by its ends in either order."""
    if kind == "time":
        return kind, (source, target)
    return kind, frozenset({source, target})


def _constraint_place(
    pattern: Pattern, place: ConstraintPlace, index_of: dict[_ConstraintKey, int]
) -> Json:
    if place.kind == "time":
        label = f"{place.first} done, for {place.second}"
        index = index_of[_constraint_key("time", place.first, place.second)]
    else:
        label = (
            f"{place.first} running, for {place.second}"
            if place.kind == "func-start"
            else f"{place.first} done, for {place.second}"
        )
        index = index_of[_constraint_key("func", place.first, place.second)]
    constraint = pattern.constraints[index]
    return {
        "label": label,
        "kind": "constraint",
        "of": [constraint.source, constraint.target],
        "constraint": {"index": index, "type": constraint.type, "role": place.kind},
        "needs": place.needed(),
    }
