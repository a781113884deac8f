"""Small runnable pattern documents for the runtime tests."""

from __future__ import annotations

import itertools
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


def _process(
    tasks: list[dict[str, Any]], arcs: list[list[str]], places: list[str]
) -> dict[str, Any]:
    return {
        "id": "N", "workpiece": "w", "actors": ["c", "o"],
        "places": [{"id": p, "tokens": 1 if p == "p0" else 0} for p in places],
        "transitions": tasks, "arcs": arcs,
    }  # fmt: skip


def _document(name: str, process: dict[str, Any], constraints: list[Any]) -> dict[str, Any]:
    return {
        "format": "hrc-pattern/1",
        "name": name,
        "actors": [
            {"id": "c", "type": "cobot", "program": PROGRAM},
            {"id": "o", "type": "operator"},
        ],
        "processes": [process],
        "constraints": constraints,
    }


def scan_until_found() -> dict[str, Any]:
    """Load; scan for a part until one is found (a guarded loop); pick it at the pose the scan
    gave; show the pose's x on the cobot's display."""
    tasks: list[dict[str, Any]] = [
        {"id": "to1", "performer": "o", "label": "load"},
        {"id": "tc_scan", "performer": "c", "label": "scan", "task": {
            "device": {"call": "part-detection.scan"},
            "outputs": {"detected": "result.detected", "pose": "result.pose"}}},
        {"id": "found", "guard": "data.detected"},
        {"id": "again", "guard": "not data.detected"},
        {"id": "tc_pick", "performer": "c", "label": "move to the part", "task": {
            "step": {"number": 2, "workspace": 0, "poses": "=[data.pose]"}}},
        {"id": "tc_show", "performer": "c", "label": "show", "task": {
            "device": {"call": "display.show", "args": {"text": "=str(data.pose[0])"}}}},
    ]  # fmt: skip
    arcs = [
        ["p0", "to1"], ["to1", "p1"], ["p1", "tc_scan"], ["tc_scan", "p2"],
        ["p2", "found"], ["found", "p3"], ["p2", "again"], ["again", "p1"],
        ["p3", "tc_pick"], ["tc_pick", "p4"], ["p4", "tc_show"], ["tc_show", "p5"],
    ]  # fmt: skip
    return _document("Scan until found", _process(tasks, arcs, [f"p{i}" for i in range(6)]), [])


def shared_space(mode: str = "pause") -> dict[str, Any]:
    """Load; then the cobot picks (tc1) while the operator inspects (to2) in a shared area."""
    tasks: list[dict[str, Any]] = [
        {"id": "to1", "performer": "o", "label": "load"},
        {"id": "split"},
        {"id": "tc1", "performer": "c", "label": "pick", "task": {
            "step": {"number": PICK}, "timeout": 30}},
        {"id": "to2", "performer": "o", "label": "inspect"},
        {"id": "join"},
    ]  # fmt: skip
    arcs = [
        ["p0", "to1"], ["to1", "p1"], ["p1", "split"], ["split", "p2"], ["split", "p3"],
        ["p2", "tc1"], ["tc1", "p4"], ["p3", "to2"], ["to2", "p5"],
        ["p4", "join"], ["p5", "join"], ["join", "p6"],
    ]  # fmt: skip
    constraint = {"from": "to2", "to": "tc1", "type": "space", "interrupt": mode}
    return _document(
        "Shared space", _process(tasks, arcs, [f"p{i}" for i in range(7)]), [constraint]
    )


def unusable_outputs() -> dict[str, Any]:
    """One cobot step (after the operator's to1) whose output expression reads a key no step
    result has: the step runs, its outputs cannot go into the case data."""
    document = cobot_chain(steps=1)
    task = document["processes"][0]["transitions"][1]["task"]
    task["outputs"] = {"grip": "result.grip_force"}
    return document


def func_hold(supported_by_cobot: bool = False) -> dict[str, Any]:
    """The cobot holds the part (tc1) while the operator screws it (to1): tc1 supports to1 (func),
    so to1 starts only while tc1 runs and tc1 completes only after to1 has. With
    `supported_by_cobot` a second cobot actor (c2) screws it instead (tc2); map both actors to
    one cobot and the cobot holds for a task it does itself."""
    supported: dict[str, Any] = (
        {"id": "tc2", "performer": "c2", "label": "screw the part", "task": {
            "step": {"number": PICK}, "timeout": 30}}
        if supported_by_cobot
        else {"id": "to1", "performer": "o", "label": "screw the part"}
    )  # fmt: skip
    tasks: list[dict[str, Any]] = [
        {"id": "split"},
        {"id": "tc1", "performer": "c", "label": "hold the part", "task": {
            "step": {"number": PICK}, "timeout": 30}},
        supported,
        {"id": "join"},
    ]  # fmt: skip
    other = supported["id"]
    arcs = [
        ["p0", "split"], ["split", "p1"], ["split", "p2"], ["p1", "tc1"], ["tc1", "p3"],
        ["p2", other], [other, "p4"], ["p3", "join"], ["p4", "join"], ["join", "p5"],
    ]  # fmt: skip
    constraint = {"from": "tc1", "to": other, "type": "func"}
    document = _document(
        "Func hold", _process(tasks, arcs, [f"p{i}" for i in range(6)]), [constraint]
    )
    if supported_by_cobot:
        document["actors"] = [
            {"id": "c", "type": "cobot", "program": PROGRAM},
            {"id": "c2", "type": "cobot", "program": PROGRAM},
        ]
        document["processes"][0]["actors"] = ["c", "c2"]
    return document


def inspection_with_deadline(timer: str = "PT5M") -> dict[str, Any]:
    """An operator inspects (to1) under a deadline: `late`, a timer on the watch place `w`,
    cancels the inspection once it has waited `timer` and sends the part to rework (to_rework);
    an inspection done in time takes the watch token back (`in_time`), which disarms it."""
    tasks: list[dict[str, Any]] = [
        {"id": "split"},
        {"id": "to1", "performer": "o", "label": "inspect"},
        {"id": "in_time"},
        {"id": "late", "label": "inspection late", "timer": timer, "cancels": ["to1", "p1", "p2"]},
        {"id": "to_rework", "performer": "o", "label": "send to rework"},
    ]
    arcs = [
        ["p0", "split"], ["split", "p1"], ["split", "w"], ["p1", "to1"], ["to1", "p2"],
        ["p2", "in_time"], ["w", "in_time"], ["in_time", "p_end"],
        ["w", "late"], ["late", "p3"], ["p3", "to_rework"], ["to_rework", "p_end"],
    ]  # fmt: skip
    places = ["p0", "p1", "p2", "p3", "w", "p_end"]
    return _operators_only("Inspection with a deadline", _process(tasks, arcs, places))


def terminate_on_alarm() -> dict[str, Any]:
    """Two operators' branches: to1 (assemble) and to2 (check the alarm); once to2 is done,
    `terminate` ends the case, cancelling to1 wherever it is (a BPMN terminate end event).
    When to1 is done first, `join` ends it normally."""
    tasks: list[dict[str, Any]] = [
        {"id": "split"},
        {"id": "to1", "performer": "o", "label": "assemble"},
        {"id": "to2", "performer": "o", "label": "check the alarm"},
        {"id": "join"},
        {"id": "terminate", "cancels": ["pa", "to1", "pa2"]},
    ]
    arcs = [
        ["p0", "split"], ["split", "pa"], ["split", "pb"], ["pa", "to1"], ["to1", "pa2"],
        ["pb", "to2"], ["to2", "pb2"], ["pa2", "join"], ["pb2", "join"], ["join", "p_end"],
        ["pb2", "terminate"], ["terminate", "p_end"],
    ]  # fmt: skip
    places = ["p0", "pa", "pa2", "pb", "pb2", "p_end"]
    return _operators_only("Terminate on alarm", _process(tasks, arcs, places))


def inspection_beside_cobot_with_deadline(timer: str = "PT5M") -> dict[str, Any]:
    """The cobot picks (tc1) while an operator inspects (to2) in the shared area, which pauses
    the pick; `late` (a timer) cancels the inspection, perhaps with the operator still there."""
    tasks: list[dict[str, Any]] = [
        {"id": "split"},
        {"id": "tc1", "performer": "c", "label": "pick", "task": {
            "step": {"number": PICK}, "timeout": 30}},
        {"id": "to2", "performer": "o", "label": "inspect"},
        {"id": "in_time"},
        {"id": "late", "label": "inspection late", "timer": timer, "cancels": ["to2", "p3", "p5"]},
        {"id": "join"},
    ]  # fmt: skip
    arcs = [
        ["p0", "split"], ["split", "p2"], ["split", "p3"], ["split", "w"],
        ["p2", "tc1"], ["tc1", "p4"], ["p3", "to2"], ["to2", "p5"],
        ["p5", "in_time"], ["w", "in_time"], ["in_time", "p6"], ["w", "late"], ["late", "p6"],
        ["p4", "join"], ["p6", "join"], ["join", "p_end"],
    ]  # fmt: skip
    places = ["p0", "p2", "p3", "p4", "p5", "p6", "w", "p_end"]
    constraint = {"from": "to2", "to": "tc1", "type": "space", "interrupt": "pause"}
    return _document("Inspection beside the cobot", _process(tasks, arcs, places), [constraint])


def _operators_only(name: str, process: dict[str, Any]) -> dict[str, Any]:
    document = _document(name, {**process, "actors": ["o"]}, [])
    document["actors"] = [{"id": "o", "type": "operator"}]
    return document


def pick_with_deadline(timer: str = "PT0.5S") -> dict[str, Any]:
    """The cobot picks (tc1, a 2 s step) under a deadline: `late` (a timer) cancels the pick
    while it runs; an operator clears the cell (to_clear) and the cobot puts the part back
    (tc2), after the cancelled pick has ended on the cobot (it is not stopped). A pick done in
    time ends the case at once (`in_time`)."""
    tasks: list[dict[str, Any]] = [
        {"id": "split"},
        {"id": "tc1", "performer": "c", "label": "pick", "task": {
            "step": {"number": PICK}, "timeout": 30}},
        {"id": "in_time"},
        {"id": "late", "label": "pick late", "timer": timer, "cancels": ["tc1", "p1", "p2"]},
        {"id": "to_clear", "performer": "o", "label": "clear the cell"},
        {"id": "tc2", "performer": "c", "label": "put back", "task": {
            "step": {"number": PICK}, "timeout": 30}},
    ]  # fmt: skip
    arcs = [
        ["p0", "split"], ["split", "p1"], ["split", "w"], ["p1", "tc1"], ["tc1", "p2"],
        ["p2", "in_time"], ["w", "in_time"], ["in_time", "p_end"],
        ["w", "late"], ["late", "p3"], ["p3", "to_clear"], ["to_clear", "p4"],
        ["p4", "tc2"], ["tc2", "p_end"],
    ]  # fmt: skip
    places = ["p0", "p1", "p2", "p3", "p4", "w", "p_end"]
    return _document("Pick with a deadline", _process(tasks, arcs, places), [])


def cool_down_then_inspect(timer: str = "PT10M") -> dict[str, Any]:
    """The part cools down (`cool_down`, a timer: BPMN's intermediate timer event) before an
    operator inspects it: at the start the case offers nothing and only waits."""
    tasks: list[dict[str, Any]] = [
        {"id": "cool_down", "label": "cooled down", "timer": timer},
        {"id": "to1", "performer": "o", "label": "inspect"},
    ]
    arcs = [["p0", "cool_down"], ["cool_down", "p1"], ["p1", "to1"], ["to1", "p2"]]
    return _operators_only("Cool down, then inspect", _process(tasks, arcs, ["p0", "p1", "p2"]))


def lanes_document(
    lanes: list[list[str]], constraints: list[tuple[str, str, str]]
) -> dict[str, Any]:
    """One lane: its tasks in sequence; more: an AND split into the lanes and their join. A
    task named tc… is the cobot's 2 s pick, to… the operator's."""
    tasks: list[dict[str, Any]] = []
    for task in itertools.chain(*lanes):
        if task.startswith("tc"):
            step = {"program": PROGRAM, "number": PICK}
            tasks.append({"id": task, "performer": "c", "task": {"step": step, "timeout": 60}})
        else:
            tasks.append({"id": task, "performer": "o"})
    places, arcs = ["p0", "p9"], []
    if len(lanes) > 1:
        tasks += [{"id": "split"}, {"id": "join"}]
        arcs += [["p0", "split"], ["join", "p9"]]
    for number, lane in enumerate(lanes):
        inner = [f"l{number}p{i}" for i in range(len(lane) + 1)]
        places += inner
        first, last = ("split", "join") if len(lanes) > 1 else ("p0", "p9")
        path = [first, *itertools.chain(*zip(inner, lane, strict=False)), inner[-1], last]
        if len(lanes) == 1:  # p0 → task → … → p9: the lane's own places only between tasks
            path = ["p0", *itertools.chain(*zip(lane, inner[1:], strict=False))]
            path[-1] = "p9"
            places = [p for p in places if p not in (inner[0], inner[-1])]
        arcs += [[a, b] for a, b in itertools.pairwise(path)]
    return {
        "format": "hrc-pattern/1",
        "name": "lanes",
        "actors": [{"id": "c", "type": "cobot", "program": PROGRAM}, {"id": "o", "type": "operator"}],
        "processes": [{
            "id": "N", "workpiece": "w", "actors": ["c", "o"],
            "places": [{"id": p, "tokens": 1 if p == "p0" else 0} for p in places],
            "transitions": tasks, "arcs": arcs,
        }],
        "constraints": [{"from": a, "to": b, "type": kind} for a, b, kind in constraints],
    }  # fmt: skip
