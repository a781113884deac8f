"""Small runnable pattern documents for the runtime tests."""

from __future__ import annotations

from typing import Any

PROGRAM = "Coexistence_PickAndPlace"
PICK = 3  # step 3 of PROGRAM: a 2 s tool wait (scaled by the gateway's time scale)


def cobot_chain(steps: int = 4, timeout: float = 5.0) -> dict[str, Any]:
    """An operator loads the cell (to1), then the cobot runs `steps` picks one after another.

    A short step timeout: a lost worker's lease (timeout + margin) expires soon.
    """
    tasks = ["to1", *(f"tc{i}" for i in range(1, steps + 1))]
    places = [f"p{i}" for i in range(len(tasks) + 1)]
    transitions: list[dict[str, Any]] = [{"id": "to1", "performer": "o", "label": "load the cell"}]
    for i in range(1, steps + 1):
        transitions.append({
            "id": f"tc{i}", "performer": "c", "label": f"pick {i}",
            "task": {"step": {"program": PROGRAM, "number": PICK}, "timeout": timeout},
        })  # fmt: skip
    arcs = []
    for index, task in enumerate(tasks):
        arcs += [[places[index], task], [task, places[index + 1]]]
    return {
        "format": "hrc-pattern/1",
        "name": f"Cobot chain of {steps}",
        "actors": [
            {"id": "c", "type": "cobot", "program": PROGRAM},
            {"id": "o", "type": "operator"},
        ],
        "processes": [
            {
                "id": "N",
                "workpiece": "w",
                "actors": ["c", "o"],
                "places": [{"id": p, "tokens": 1 if p == "p0" else 0} for p in places],
                "transitions": transitions,
                "arcs": arcs,
            }
        ],
        "constraints": [],
    }
