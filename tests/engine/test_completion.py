"""`"completion": "implicit"`: a process has completed once all its tokens lie in its sink place.

BPMN's rule (each end event consumes its token), so branches of a parallel split may end
separately; the check, the runtime and the token game read the key per process.
"""

import copy
from typing import Any

from hrc.engine.bpmn import bpmn_to_document, bpmn_to_pattern
from hrc.engine.bpmn_export import pattern_to_bpmn
from hrc.engine.check import check_document, check_pattern
from hrc.engine.document import read_pattern
from hrc.engine.execution import build_execution_net
from hrc.engine.petri import Marking
from hrc.engine.runtime import CaseNet
from hrc.engine.tokengame import execution_net_json
from tests.engine.builders import document, process
from tests.engine.test_bpmn import bpmn, flows

Doc = dict[str, Any]

OPERATORS = {"ta": "o", "tb": "o", "tl": "o"}


def _implicit(data: Doc, *processes: str) -> Doc:
    """A copy of data whose named processes (all, when none is named) complete implicitly."""
    data = copy.deepcopy(data)
    for net in data["processes"]:
        if not processes or net["id"] in processes:
            net["completion"] = "implicit"
    return data


def _two_ends(process_id: str = "N", suffix: str = "") -> Doc:
    """An AND-split xs whose branches ta and tb end at two end steps xea, xeb into the sink."""
    s = suffix
    return process(
        process_id,
        f"p0{s} xs{s} pa{s} ta{s} pa2{s} xea{s} p9{s}",
        f"xs{s} pb{s} tb{s} pb2{s} xeb{s} p9{s}",
        performers={f"ta{s}": "o", f"tb{s}": "o"},
    )


def test_two_branches_ending_separately_are_unsound_by_default_and_sound_when_implicit() -> None:
    data = document(_two_ends())

    proper, implicit = check_document(data), check_document(_implicit(data))

    assert proper.sound is False
    assert "end place p9 holds 2 tokens where a finished case leaves 1 token" in " ".join(
        e.message for e in proper.errors
    )
    assert implicit.sound is True
    assert implicit.valid, implicit.errors


def test_a_branch_that_can_run_forever_keeps_an_implicit_process_unsound() -> None:
    # Branch a ends at once (xa1) or hands pq to branch b (xa2); b loops on tl and can only
    # leave through xj, which needs pq. Once a has ended, b runs on and never completes.
    data = document(
        process(
            "N",
            "p0 xs pa xa1 p9",
            "pa xa2 pq xj p9",
            "xs pb tb pc tl pc",
            "pc xj",
            performers=OPERATORS,
        )
    )

    report = check_document(_implicit(data))

    assert report.sound is False
    assert [e.code for e in report.errors] == ["unsound"]
    assert "loop without end" in report.errors[0].message


def test_a_task_still_running_at_the_end_is_no_completion() -> None:
    net = build_execution_net(read_pattern(_implicit(document(_two_ends()))))

    assert net.is_final(Marking({"p9": 2}))
    assert net.is_final(Marking({"p9": 1}))
    assert not net.is_final(Marking({"p9": 1, "running:tb": 1}))
    assert not net.is_final(Marking({"p9": 1, "pb": 1}))
    assert not net.is_final(Marking())


def test_a_loop_that_ends_a_branch_each_round_is_bounded_when_implicit() -> None:
    # Each round of tl forks xr: one token ends, one goes round again; xo leaves the loop.
    data = document(process("N", "p0 x0 pl tl pm xr p9", "xr pl", "pm xo p9", performers=OPERATORS))

    proper, implicit = check_document(data), check_document(_implicit(data))

    assert "unbounded" in [e.code for e in proper.errors]
    assert implicit.sound is True, implicit.errors


def test_each_process_of_a_coexistence_pattern_keeps_its_own_completion() -> None:
    data = document(_two_ends("A", "1"), _two_ends("B", "2"))

    both, only_b = check_document(_implicit(data)), check_document(_implicit(data, "B"))

    assert both.sound is True
    assert only_b.sound is False
    left_over = [e for e in only_b.errors if "left over" in e.message]
    assert [e.elements for e in left_over] == [("p91",)]


def test_a_completion_other_than_proper_or_implicit_is_a_format_error() -> None:
    data = document(_two_ends())
    data["processes"][0]["completion"] = "whenever"

    report = check_document(data)

    assert [(e.code, e.elements) for e in report.errors] == [("format", ("N",))]
    assert "'whenever'" in report.errors[0].message
    assert report.sound is None


def test_the_token_game_knows_which_end_may_hold_several_tokens() -> None:
    data = document(_two_ends("A", "1"), _two_ends("B", "2"))

    game = execution_net_json(read_pattern(_implicit(data, "B")))

    assert game["open_ends"] == ["p92"]
    assert game["final"] == {"p91": 1, "p92": 1}


PARALLEL_ENDS = bpmn(
    '<startEvent id="s"/><parallelGateway id="g"/>'
    '<task id="a" name="Pack"/><task id="b" name="Label"/>'
    '<endEvent id="ea" name="Packed"/><endEvent id="eb" name="Labelled"/>'
    + flows("f1: s -> g", "f2: g -> a", "f3: g -> b", "f4: a -> ea", "f5: b -> eb")
)


def test_a_bpmn_process_whose_branches_end_at_two_end_events_imports_sound() -> None:
    pattern = bpmn_to_pattern(PARALLEL_ENDS)

    assert pattern.processes[0].completes_implicitly
    report = check_pattern(pattern)
    assert report.sound is True, report.errors


def test_a_case_of_it_completes_when_both_branches_have_ended() -> None:
    case = CaseNet(bpmn_to_pattern(PARALLEL_ENDS))
    marking, _ = case.settle(case.initial, {})
    assert sorted(case.startable(marking)) == ["a", "b"]

    marking, _ = case.settle(case.complete(case.start(marking, "a"), "a"), {})
    assert not case.is_final(marking)
    marking = case.start(marking, "b")
    assert not case.is_final(marking)
    marking, _ = case.settle(case.complete(marking, "b"), {})

    assert case.is_final(marking)
    assert sum(marking.values()) == 2  # Both end events' tokens, in the one sink place.


def test_hrc_extra_on_the_process_overrides_the_bpmn_rule() -> None:
    text = PARALLEL_ENDS.replace(
        '<process id="P" name="Test process">',
        '<process id="P" name="Test process"><extensionElements>'
        '<hrc:extra>{"completion": "proper"}</hrc:extra></extensionElements>',
    )

    pattern = bpmn_to_pattern(text)

    assert not pattern.processes[0].completes_implicitly
    assert check_pattern(pattern).sound is False


def test_a_round_trip_through_bpmn_keeps_each_process_rule_and_adds_none() -> None:
    proper = read_pattern(document(process("N", "p0 ta p9", performers=OPERATORS)))
    implicit = read_pattern(_implicit(document(_two_ends())))

    back_proper = bpmn_to_document(pattern_to_bpmn(proper))
    back_implicit = bpmn_to_pattern(pattern_to_bpmn(implicit))

    assert "completion" not in back_proper["processes"][0]
    assert back_implicit.processes[0].completes_implicitly
    assert check_pattern(back_implicit).sound is True
