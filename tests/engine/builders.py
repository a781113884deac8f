"""Small `hrc-pattern/1` documents for engine tests, built from a compact description.

`net("p1 t1 p2", "p2 t2 p3")` reads each string as a path of alternating
nodes; ids starting with `p` are places, anything else a transition. Tasks
get performers from `performers`; everything else is silent.
"""

import itertools
import json
from pathlib import Path
from typing import Any

EXAMPLES = Path(__file__).resolve().parents[2] / "hrc" / "patterns" / "examples"


def example(name: str) -> dict[str, Any]:
    """One document of the shipped example library, by file stem."""
    data: dict[str, Any] = json.loads((EXAMPLES / f"{name}.json").read_text())
    return data


def process(
    process_id: str,
    *paths: str,
    performers: dict[str, str],
    workpiece: str = "w",
) -> dict[str, Any]:
    places: list[str] = []
    transitions: list[str] = []
    arcs: list[list[str]] = []
    for path in paths:
        nodes = path.split()
        for node in nodes:
            bucket = places if node.startswith("p") else transitions
            if node not in bucket:
                bucket.append(node)
        arcs += [[a, b] for a, b in itertools.pairwise(nodes) if [a, b] not in arcs]
    return {
        "id": process_id,
        "workpiece": workpiece,
        "actors": sorted({performers[t] for t in transitions if t in performers}),
        "places": [{"id": p} for p in places],
        "transitions": [
            {"id": t, **({"performer": performers[t]} if t in performers else {})}
            for t in transitions
        ],
        "arcs": arcs,
    }


PROGRAM = "Coexistence_PickAndPlace"


def document(
    *processes: dict[str, Any],
    constraints: list[tuple[str, str, str]] = (),  # type: ignore[assignment]
    actors: dict[str, str] | None = None,
    declared: str | None = None,
) -> dict[str, Any]:
    """A document; actors default to every performer, `c…` a cobot and anything else an operator.

    Each cobot runs PROGRAM (a cobot task must name its program to be checked clean)."""
    if actors is None:
        names = sorted({a for p in processes for a in p["actors"]})
        actors = {a: "cobot" if a.startswith("c") else "operator" for a in names}
    data: dict[str, Any] = {
        "format": "hrc-pattern/1",
        "name": "test",
        "actors": [
            {"id": a, "type": t, **({"program": PROGRAM} if t == "cobot" else {})}
            for a, t in actors.items()
        ],
        "processes": list(processes),
        "constraints": [{"from": a, "to": b, "type": t} for a, b, t in constraints],
    }
    if declared:
        data["declared_pattern"] = declared
    return data


def two_lanes(
    constraints: list[tuple[str, str, str]], declared: str | None = None
) -> dict[str, Any]:
    """An AND-split into a cobot lane (tc1→tc2→tc3) and an operator lane (to1→to2), joined again."""
    lanes = process(
        "N",
        "p1 t1 p2 tc1 p3 tc2 p4 tc3 p5 t2 p9",
        "t1 p6 to1 p7 to2 p8 t2",
        performers={"tc1": "c", "tc2": "c", "tc3": "c", "to1": "o", "to2": "o"},
    )
    return document(lanes, constraints=constraints, declared=declared)


def parallel_lanes(pairs: int, length: int) -> dict[str, Any]:
    """A pattern built for a huge state space: `2 × pairs` parallel lanes of `length` tasks.

    The second lane of each pair waits for the first through a time constraint
    per task, which keeps the reduction from collapsing the lanes, while the
    pairs stay independent of each other: about `(length²/2)^pairs` markings.
    `parallel_lanes(10, 8)` is a 20 KB document with millions of markings,
    the probe's check that took 9 s of CPU.
    """
    chains, performers = [], {}
    constraints: list[tuple[str, str, str]] = []
    for lane in range(2 * pairs):
        tasks = [f"t{lane}_{i}" for i in range(length)]
        path = " ".join(f"p{lane}_{i} {task}" for i, task in enumerate(tasks))
        chains.append(f"ps tsplit {path} pj{lane} tjoin pe")
        performers.update({task: f"{'o' if lane % 2 == 0 else 'c'}{lane}" for task in tasks})
        if lane % 2:
            constraints += [(f"t{lane - 1}_{i}", f"t{lane}_{i}", "time") for i in range(length)]
    return document(process("N", *chains, performers=performers), constraints=constraints)


def with_keys(data: dict[str, Any], **keys: dict[str, Any]) -> dict[str, Any]:
    """data with keys added to transitions: `xt={"timer": "PT1M"}`."""
    for net in data["processes"]:
        for transition in net["transitions"]:
            transition.update(keys.get(transition["id"], {}))
    return data


def guarded_task(cancels: list[str]) -> dict[str, Any]:
    """An interrupting timer on the cobot's task ta: xf forks the task and a watch pw; xok ends
    the watch once ta is done; xt rings after 10 s and cancels `cancels`, xto leads on."""
    data = document(
        process(
            "N",
            "p0 xf pt ta pd xok p9",
            "xf pw xt px xto p9",
            "pw xok",
            performers={"ta": "c"},
        )
    )
    return with_keys(data, xt={"timer": "PT10S", "cancels": cancels})
