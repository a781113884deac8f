"""Every rule of pattern-format.md, each with a model that breaks it and nothing else."""

import copy
import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from hrc.engine import check_document
from hrc.engine.issues import ERROR_CODES
from tests.engine.builders import EXAMPLES, document, process, two_lanes

Doc = dict[str, Any]


def _mutated(change: Callable[[Doc], None]) -> Doc:
    data = two_lanes([("to1", "tc2", "time")])
    change(data)
    return data


def _net(data: Doc) -> Doc:
    net: Doc = data["processes"][0]
    return net


def _duplicate_id(data: Doc) -> None:
    _net(data)["places"].append({"id": "tc1"})
    _net(data)["arcs"].append(["tc3", "tc1"])


def _rename_sink_to_collide(data: Doc) -> None:
    data["actors"].append({"id": "N", "type": "cobot"})


def _arc_to_nowhere(data: Doc) -> None:
    _net(data)["arcs"].append(["tc1", "p42"])


def _arc_between_places(data: Doc) -> None:
    _net(data)["arcs"].append(["p2", "p3"])


def _unknown_performer(data: Doc) -> None:
    _net(data)["transitions"][2]["performer"] = "c9"


def _unassigned_actor(data: Doc) -> None:
    data["actors"].append({"id": "c2", "type": "cobot"})


def _idle_actor(data: Doc) -> None:
    data["actors"].append({"id": "o2", "type": "operator"})
    _net(data)["actors"].append("o2")


def _self_constraint(data: Doc) -> None:
    data["constraints"].append({"from": "tc1", "to": "tc1", "type": "time"})


def _unperformed_constraint(data: Doc) -> None:
    data["constraints"].append({"from": "t1", "to": "to2", "type": "time"})


def _same_performer_constraint(data: Doc) -> None:
    data["constraints"].append({"from": "tc1", "to": "tc3", "type": "time"})


def _constraint_type(data: Doc) -> None:
    data["constraints"].append({"from": "tc1", "to": "to2", "type": "temporal"})


def _duplicate_constraint(data: Doc) -> None:
    data["constraints"].append({"from": "to1", "to": "tc2", "type": "time"})


def _conflicting_constraint(data: Doc) -> None:
    data["constraints"].append({"from": "to1", "to": "tc2", "type": "space"})


def _no_actors(data: Doc) -> None:
    data["actors"] = []


def _actorless_process(data: Doc) -> None:
    data["processes"].append(_actorless())


def _no_workpiece(data: Doc) -> None:
    del _net(data)["workpiece"]


def _two_sinks(data: Doc) -> None:
    _net(data)["places"].append({"id": "p10"})
    _net(data)["arcs"].append(["tc1", "p10"])


def _stray_cycle(data: Doc) -> None:
    _net(data)["places"].append({"id": "p10"})
    _net(data)["transitions"].append({"id": "t3"})
    _net(data)["arcs"] += [["p10", "t3"], ["t3", "p10"]]


def _declared_wrongly(data: Doc) -> None:
    data["declared_pattern"] = "cooperation"


def _bad_task_config(data: Doc) -> None:
    task = next(t for t in _net(data)["transitions"] if t["id"] == "tc1")
    task["task"] = {"step": {"number": "=data.step +"}}


def _to_rewrite(data: Doc) -> None:
    split = next(t for t in _net(data)["transitions"] if t["id"] == "t1")
    split["rewrite"] = "the condition ${count > 3 && ok} is in JUEL"


def _deadlock(data: Doc) -> None:
    data["constraints"].append({"from": "tc3", "to": "to1", "type": "time"})


def _unbounded(data: Doc) -> None:
    # A loop around the cobot's first task: every round adds a token for tc2.
    _net(data)["transitions"].append({"id": "t3"})
    _net(data)["arcs"] += [["p3", "t3"], ["t3", "p2"], ["t3", "p3"]]


CASES: list[tuple[str, Callable[[Doc], None], str, set[str]]] = [
    ("duplicate id across places and transitions", _duplicate_id, "duplicate-id", {"tc1"}),
    ("duplicate id across actors and processes", _rename_sink_to_collide, "duplicate-id", {"N"}),
    ("arc names a node that does not exist", _arc_to_nowhere, "unknown-node", {"p42"}),
    ("arc joins two places", _arc_between_places, "arc-kind", {"p2", "p3"}),
    ("performer is not an actor", _unknown_performer, "unknown-actor", {"c9"}),
    ("actor in no process", _unassigned_actor, "unassigned-actor", {"c2"}),
    ("assigned actor performs nothing", _idle_actor, "idle-actor", {"o2"}),
    ("constraint joins a task to itself", _self_constraint, "constraint-self", {"tc1"}),
    (
        "constraint on a silent transition",
        _unperformed_constraint,
        "constraint-unperformed",
        {"t1"},
    ),
    (
        "constraint between one actor's tasks",
        _same_performer_constraint,
        "constraint-same-performer",
        {"tc1", "tc3"},
    ),
    ("constraint of an unknown type", _constraint_type, "constraint-type", {"tc1", "to2"}),
    ("the same constraint twice", _duplicate_constraint, "constraint-duplicate", {"to1", "tc2"}),
    (
        "two types on one ordered pair",
        _conflicting_constraint,
        "constraint-conflict",
        {"to1", "tc2"},
    ),
    ("a pattern without actors", _no_actors, "no-actors", {"N"}),
    ("a process without actors", _actorless_process, "no-actors", {"N2"}),
    ("a process without a workpiece", _no_workpiece, "unassigned-workpiece", {"N"}),
    ("process with two sink places", _two_sinks, "not-workflow-net", {"p9", "p10"}),
    ("node on no path from source to sink", _stray_cycle, "not-workflow-net", {"p10", "t3"}),
    ("declared pattern does not hold", _declared_wrongly, "pattern-mismatch", set()),
    ("a task configuration that cannot run", _bad_task_config, "task-config", {"tc1"}),
    ("an imported piece still to rewrite", _to_rewrite, "to-rewrite", {"t1"}),
    ("time constraints against each other", _deadlock, "unsound", {"tc2", "to1"}),
    ("a loop that adds a token each round", _unbounded, "unbounded", set()),
]


@pytest.mark.parametrize(
    ("change", "code", "elements"), [c[1:] for c in CASES], ids=[c[0] for c in CASES]
)
def test_each_broken_rule_is_reported_with_its_code_and_elements(
    change: Callable[[Doc], None], code: str, elements: set[str]
) -> None:
    report = check_document(_mutated(change))

    codes = [issue.code for issue in report.errors]
    assert code in codes, report.as_dict()
    issue = next(i for i in report.errors if i.code == code)
    assert elements <= set(issue.elements)
    assert len(issue.message) > 20
    assert report.valid is False


def _actorless() -> Doc:
    """A second process of one silent transition, which needs no actor to be a workflow net."""
    return {
        "id": "N2",
        "workpiece": "w2",
        "actors": [],
        "places": [{"id": "q1"}, {"id": "q2"}],
        "transitions": [{"id": "u1"}],
        "arcs": [["q1", "u1"], ["u1", "q2"]],
    }


NEW_RULES = [
    (_duplicate_constraint, "constraint-duplicate", ("to1", "tc2")),
    (_conflicting_constraint, "constraint-conflict", ("to1", "tc2")),
    (_actorless_process, "no-actors", ("N2",)),
    (_no_workpiece, "unassigned-workpiece", ("N",)),
]


@pytest.mark.parametrize(("change", "code", "elements"), NEW_RULES, ids=[r[1] for r in NEW_RULES])
def test_a_model_breaking_one_new_rule_gets_exactly_that_code(
    change: Callable[[Doc], None], code: str, elements: tuple[str, ...]
) -> None:
    report = check_document(_mutated(change))

    assert [(i.code, i.elements) for i in report.errors] == [(code, elements)]
    assert report.sound is None


def test_a_pattern_without_actors_is_an_error_not_just_a_warning() -> None:
    data = _mutated(_no_actors)
    for transition in _net(data)["transitions"]:
        transition.pop("performer", None)
    _net(data)["actors"] = []
    data["constraints"] = []

    report = check_document(data)

    assert [(i.code, i.elements) for i in report.errors] == [("no-actors", ("N",))]
    assert report.errors[0].message.startswith("The pattern has no actors")


def test_a_constraint_in_both_directions_is_no_conflict() -> None:
    report = check_document(two_lanes([("to1", "tc2", "time"), ("tc2", "to2", "space")]))

    codes = {i.code for i in report.errors}
    assert not codes & {"constraint-conflict", "constraint-duplicate"}, report.as_dict()


def test_a_duplicate_constraint_names_its_tasks_and_how_often_it_is_drawn() -> None:
    data = _labelled(_mutated(_duplicate_constraint))
    _duplicate_constraint(data)

    issue = next(i for i in check_document(data).errors if i.code == "constraint-duplicate")

    assert issue.message.startswith(
        "The time constraint “Prepare workpiece” → “Place insert” is drawn 3 times"
    )


def test_a_conflict_names_the_types_on_the_pair() -> None:
    data = _labelled(_mutated(_conflicting_constraint))

    issue = next(i for i in check_document(data).errors if i.code == "constraint-conflict")

    assert "“Prepare workpiece” → “Place insert”" in issue.message
    assert "2 types (time, space)" in issue.message


def test_the_unmutated_model_breaks_no_rule() -> None:
    report = check_document(_mutated(lambda data: None))

    assert report.errors == ()
    assert report.valid is True
    assert report.sound is True


def test_every_error_code_has_a_case_here_or_in_the_format_tests() -> None:
    covered = {case[2] for case in CASES} | {"format"}  # format: tests/engine/test_document.py
    assert set(ERROR_CODES) == covered


def test_each_rewrite_note_is_an_error_that_quotes_it_and_leaves_soundness_decided() -> None:
    data = _mutated(_to_rewrite)
    _net(data)["places"][3]["label"] = "tray full"
    _net(data)["places"][3]["rewrite"] = True

    report = check_document(data)

    assert [(i.code, i.elements, i.message) for i in report.errors] == [
        (
            "to-rewrite",
            ("p4",),
            "Place “tray full” needs rewriting. Rewrite it in hrc's terms, then remove its "
            "'rewrite' key.",
        ),
        (
            "to-rewrite",
            ("t1",),
            "Split/join t1 needs rewriting: the condition ${count > 3 && ok} is in JUEL. "
            "Rewrite it in hrc's terms, then remove its 'rewrite' key.",
        ),
    ]
    assert report.valid is False
    assert report.sound is True


def test_a_broken_rule_leaves_soundness_undecided() -> None:
    report = check_document(_mutated(_arc_between_places))

    assert report.sound is None


def test_all_broken_rules_are_reported_at_once() -> None:
    data = _mutated(_arc_between_places)
    _self_constraint(data)
    _unassigned_actor(data)

    codes = {issue.code for issue in check_document(data).errors}

    assert {"arc-kind", "constraint-self", "unassigned-actor"} <= codes


def test_an_arc_into_another_process_names_that_process() -> None:
    first = process("N1", "p11 tc1 p12", performers={"tc1": "c"}, workpiece="w1")
    second = process("N2", "p21 to1 p22", performers={"to1": "o"}, workpiece="w2")
    second["arcs"].append(["to1", "p12"])

    report = check_document(document(first, second))

    issue = next(i for i in report.errors if i.code == "unknown-node")
    assert "belongs to process N1" in issue.message


def test_mutations_do_not_leak_between_cases() -> None:
    base = two_lanes([("to1", "tc2", "time")])
    copied = copy.deepcopy(base)

    _duplicate_id(copied)

    assert base != copied


def _labelled(data: Doc) -> Doc:
    labels = {"tc1": "Pick insert", "tc2": "Place insert", "to1": "Prepare workpiece"}
    for transition in _net(data)["transitions"]:
        if transition["id"] in labels:
            transition["label"] = labels[transition["id"]]
    return data


def test_a_loose_place_is_explained_as_a_start_too_many_in_the_drawing() -> None:
    data = _labelled(two_lanes([("to1", "tc2", "time")]))
    _net(data)["places"].append({"id": "p42", "label": "Tray"})

    issue = next(i for i in check_document(data).errors if i.code == "not-workflow-net")

    assert issue.message.startswith(
        "The drawing has 2 places where a case could start (place p1 and place “Tray”"
    )
    assert "2 places where a case could end" in issue.message
    assert "source places" not in issue.message
    assert "(none)" not in issue.message
    assert "p42" in issue.elements


def test_a_constraint_broken_rule_names_the_tasks_by_their_labels() -> None:
    data = _labelled(two_lanes([("tc1", "tc2", "time")]))

    issue = next(i for i in check_document(data).errors if i.code == "constraint-same-performer")

    assert issue.message.startswith(
        "The time constraint “Pick insert” → “Place insert” joins two tasks of the same cobot c"
    )
    assert issue.elements == ("tc1", "tc2")


def test_a_deadlock_is_told_in_task_names_with_the_constraint_that_holds_it() -> None:
    data = _labelled(two_lanes([("to1", "tc2", "time"), ("tc3", "to1", "time")]))

    issue = next(i for i in check_document(data).errors if i.code == "unsound")

    assert issue.message.startswith(
        "The pattern can get stuck: after split/join t1 fires, “Pick insert” starts, "
        "“Pick insert” completes, nothing more can happen"
    )
    assert (
        "The start of “Place insert” waits for a completion of “Prepare workpiece” "
        "(time constraint “Prepare workpiece” → “Place insert”)"
    ) in issue.message
    assert issue.witness == ("t1", "start tc1", "complete tc1")  # ids, for the editor's replay


def test_an_arc_between_two_places_says_what_to_put_between_them() -> None:
    data = _mutated(_arc_between_places)

    issue = next(i for i in check_document(data).errors if i.code == "arc-kind")

    assert issue.message.startswith("The arrow from place p2 to place p3 joins two places")
    assert issue.elements == ("p2", "p3")


THESIS_INSTANTIATIONS = sorted(EXAMPLES.glob("*.json"))
USE_CASES = sorted((EXAMPLES / "use_cases").glob("*.json"))


def test_the_shipped_library_has_the_eight_instantiations_and_seven_use_cases() -> None:
    assert len(THESIS_INSTANTIATIONS) == 8
    assert len(USE_CASES) >= 7


@pytest.mark.parametrize(
    "path", THESIS_INSTANTIATIONS + USE_CASES, ids=lambda path: f"{path.parent.name}/{path.stem}"
)
def test_every_shipped_document_keeps_every_rule(path: Path) -> None:
    report = check_document(json.loads(path.read_text(encoding="utf-8")))

    assert report.errors == (), report.as_dict()
    assert report.valid is True
