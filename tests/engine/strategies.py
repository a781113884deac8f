"""Hypothesis strategies for generated collaboration patterns.

Processes are built from blocks (task, sequence, AND, XOR, loop), so they
are workflow nets by construction; random constraints and the odd extra arc
then make many of them unsound, which is what the soundness property needs:
a good mix of both verdicts.
"""

from typing import Any

from hypothesis import strategies as st

ACTORS = {"c1": "cobot", "c2": "cobot", "o1": "operator", "o2": "operator"}
JSON_VALUES = st.recursive(
    st.none() | st.booleans() | st.integers(-1000, 1000) | st.text(max_size=8),
    lambda inner: (
        st.lists(inner, max_size=3) | st.dictionaries(st.text(max_size=5), inner, max_size=3)
    ),
    max_leaves=6,
)
EXTRA_KEYS = st.text(min_size=1, max_size=6).filter(
    lambda k: (
        k
        not in {
            "id",
            "type",
            "tokens",
            "performer",
            "label",
            "from",
            "to",
            "workpiece",
            "actors",
            "places",
            "transitions",
            "arcs",
            "format",
            "name",
            "declared_pattern",
            "processes",
            "constraints",
        }
    )
)
EXTRAS = st.dictionaries(EXTRA_KEYS, JSON_VALUES, max_size=2)


class _Builder:
    def __init__(self) -> None:
        self.places: list[str] = []
        self.transitions: list[dict[str, Any]] = []
        self.arcs: list[list[str]] = []

    def place(self) -> str:
        place = f"p{len(self.places) + 1}"
        self.places.append(place)
        return place

    def transition(self, performer: str | None) -> str:
        transition = f"t{len(self.transitions) + 1}"
        self.transitions.append(
            {"id": transition, **({"performer": performer} if performer else {})}
        )
        return transition

    def arc(self, source: str, target: str) -> None:
        self.arcs.append([source, target])


@st.composite
def _block(draw: st.DrawFn, builder: _Builder, entry: str, exit_: str, depth: int) -> None:
    kind = draw(
        st.sampled_from(["task", "task", "seq", "and", "xor", "loop"] if depth < 2 else ["task"])
    )
    if kind == "task":
        task = builder.transition(draw(st.sampled_from(sorted(ACTORS))))
        builder.arc(entry, task)
        builder.arc(task, exit_)
    elif kind == "seq":
        middle = builder.place()
        draw(_block(builder, entry, middle, depth + 1))
        draw(_block(builder, middle, exit_, depth + 1))
    elif kind == "and":
        split, join = builder.transition(None), builder.transition(None)
        builder.arc(entry, split)
        builder.arc(join, exit_)
        for _ in range(draw(st.integers(2, 3))):
            start, end = builder.place(), builder.place()
            builder.arc(split, start)
            builder.arc(end, join)
            draw(_block(builder, start, end, depth + 1))
    elif kind == "xor":
        draw(_block(builder, entry, exit_, depth + 1))
        draw(_block(builder, entry, exit_, depth + 1))
    else:
        # The loop gets its own head place, so that redoing never re-enters the source.
        head, middle, enter = builder.place(), builder.place(), builder.transition(None)
        builder.arc(entry, enter)
        builder.arc(enter, head)
        draw(_block(builder, head, middle, depth + 1))
        redo = builder.transition(draw(st.sampled_from(sorted(ACTORS))))
        builder.arc(middle, redo)
        builder.arc(redo, head)
        leave = builder.transition(None)
        builder.arc(middle, leave)
        builder.arc(leave, exit_)


@st.composite
def patterns(draw: st.DrawFn, mutate: bool = True) -> dict[str, Any]:
    """A one-process pattern document that passes every structural rule."""
    builder = _Builder()
    source, sink = builder.place(), builder.place()
    draw(_block(builder, source, sink, 0))
    if mutate and draw(st.booleans()):
        # An extra output arc: can leave tokens behind or let them pile up.
        transition = draw(st.sampled_from(builder.transitions))["id"]
        target = draw(st.sampled_from([p for p in builder.places if p != source]))
        if [transition, target] not in builder.arcs:
            builder.arc(transition, target)
    tasks = [t for t in builder.transitions if "performer" in t]
    constraints: list[dict[str, str]] = []
    for _ in range(draw(st.integers(0, 3))):
        a, b = draw(st.sampled_from(tasks)), draw(st.sampled_from(tasks))
        # constr is a partial function: one constraint per ordered pair of tasks.
        taken = {(c["from"], c["to"]) for c in constraints}
        if a["performer"] != b["performer"] and (a["id"], b["id"]) not in taken:
            kind = draw(st.sampled_from(["time", "func", "space"]))
            constraints.append({"from": a["id"], "to": b["id"], "type": kind})
    actors = sorted({t["performer"] for t in tasks})
    return {
        "format": "hrc-pattern/1",
        "name": "generated",
        "actors": [{"id": a, "type": ACTORS[a]} for a in actors],
        "processes": [
            {
                "id": "N",
                "workpiece": "w",
                "actors": actors,
                "places": [{"id": p} for p in builder.places],
                "transitions": builder.transitions,
                "arcs": builder.arcs,
            }
        ],
        "constraints": constraints,
    }


@st.composite
def decorated(draw: st.DrawFn) -> dict[str, Any]:
    """A generated pattern with unknown keys on every kind of element, as the editor writes them."""
    data = draw(patterns(mutate=False))
    data.update(draw(EXTRAS))
    for element in data["actors"] + data["constraints"] + data["processes"]:
        element.update(draw(EXTRAS))
    process = data["processes"][0]
    for element in process["places"] + process["transitions"]:
        element.update(draw(EXTRAS))
    if draw(st.booleans()):
        process["places"][0]["tokens"] = draw(st.integers(0, 3))
    return data


@st.composite
def cancelling(draw: st.DrawFn) -> dict[str, Any]:
    """A generated pattern whose silent transitions may cancel some of its places and tasks, and
    maybe one more like a terminate end: from a place straight to the end, cancelling everything."""
    data = draw(patterns())
    process = data["processes"][0]
    places = [p["id"] for p in process["places"]]
    nodes = places + [t["id"] for t in process["transitions"]]
    if draw(st.booleans()):
        # places[1] is the end place; every other one lies on a way to it.
        place = draw(st.sampled_from([p for p in places if p != places[1]]))
        process["transitions"].append({"id": "tx", "cancels": list(nodes)})
        process["arcs"] += [[place, "tx"], ["tx", places[1]]]
    for transition in process["transitions"]:
        if "performer" not in transition and "cancels" not in transition and draw(st.booleans()):
            transition["cancels"] = draw(st.lists(st.sampled_from(nodes), max_size=4))
    return data
