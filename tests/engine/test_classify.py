"""The four patterns (thesis 4.2.1–4.2.4), the vacuous case, and a declared pattern that fails."""

from hrc.engine import check_document
from tests.engine.builders import document, example, process, two_lanes


def _patterns(data: dict[str, object]) -> list[str]:
    return list(check_document(data).patterns)


def test_time_constraints_make_it_synchronized() -> None:
    assert _patterns(two_lanes([("to1", "tc2", "time")])) == ["synchronized"]


def test_space_constraints_make_it_cooperation() -> None:
    assert _patterns(two_lanes([("tc1", "to1", "space")])) == ["cooperation"]


def test_func_constraints_make_it_collaboration() -> None:
    assert _patterns(two_lanes([("tc2", "to1", "func")])) == ["collaboration"]


def test_separate_one_actor_processes_make_it_coexistence() -> None:
    assert _patterns(example("coex_2o1c_packaging_palletizing")) == ["coexistence"]


def test_no_constraints_fit_three_patterns_with_a_warning() -> None:
    report = check_document(two_lanes([]))

    assert report.patterns == ("synchronized", "cooperation", "collaboration")
    assert [w.code for w in report.warnings] == ["vacuous-pattern"]
    assert report.valid is True


def test_mixed_constraint_types_fit_no_pattern_and_say_why() -> None:
    report = check_document(two_lanes([("to1", "tc2", "time"), ("tc1", "to2", "space")]))

    assert report.patterns == ()
    warning = next(w for w in report.warnings if w.code == "no-pattern")
    assert (
        "every constraint must be a time constraint, the model has space constraints"
        in warning.message
    )


def test_a_single_actor_type_is_no_pattern() -> None:
    net = process("N", "p1 tc1 p2 tc2 p3", performers={"tc1": "c1", "tc2": "c2"})

    report = check_document(document(net, constraints=[("tc1", "tc2", "time")]))

    assert report.patterns == ()
    assert "at least one operator" in report.warnings[0].message


def test_coexistence_needs_disjoint_actors_and_no_constraints() -> None:
    first = process("N1", "p11 tc1 p12", performers={"tc1": "c"}, workpiece="w1")
    second = process("N2", "p21 to1 p22", performers={"to1": "o"}, workpiece="w2")

    report = check_document(
        document(first, second, constraints=[("tc1", "to1", "time")], declared="coexistence")
    )

    mismatch = next(e for e in report.errors if e.code == "pattern-mismatch")
    assert "allows no constraints, the model has 1" in mismatch.message


def test_coexistence_processes_must_not_share_a_workpiece() -> None:
    first = process("N1", "p11 tc1 p12", performers={"tc1": "c"}, workpiece="w")
    second = process("N2", "p21 to1 p22", performers={"to1": "o"}, workpiece="w")

    report = check_document(document(first, second))

    assert report.patterns == ()


def test_coexistence_does_not_skip_a_process_without_a_workpiece() -> None:
    first = process("N1", "p11 tc1 p12", performers={"tc1": "c"}, workpiece="w1")
    second = process("N2", "p21 to1 p22", performers={"to1": "o"})
    del second["workpiece"]

    report = check_document(document(first, second, declared="coexistence"))

    assert report.patterns == ()
    codes = [(e.code, e.elements) for e in report.errors]
    assert ("unassigned-workpiece", ("N2",)) in codes
    mismatch = next(e for e in report.errors if e.code == "pattern-mismatch")
    assert "each process needs its own workpiece, N2 has none" in mismatch.message


def test_a_declared_pattern_that_does_not_hold_is_an_error_naming_the_failed_requirement() -> None:
    report = check_document(two_lanes([("to1", "tc2", "time")], declared="collaboration"))

    mismatch = next(e for e in report.errors if e.code == "pattern-mismatch")
    assert "declared collaboration" in mismatch.message
    assert (
        "every constraint must be a func constraint, the model has time constraints"
        in mismatch.message
    )
    assert "(it is synchronized)" in mismatch.message
    assert report.sound is True  # the behaviour is still decided
