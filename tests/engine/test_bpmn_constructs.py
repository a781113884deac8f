"""BPMN constructs of real models: sub-processes, call activities, events, gateways, conditions.

Each test imports a small hand-written snippet and runs or checks the net it
becomes, so the mapping's behaviour is asserted, not just its shape.
"""

from typing import Any

from hrc.engine.bpmn import BPMN_NAMESPACE, bpmn_to_pattern
from hrc.engine.check import check_pattern
from hrc.engine.document import FormatError
from hrc.engine.model import Pattern
from hrc.engine.runtime import CaseNet
from tests.engine.test_bpmn import bpmn, flows, refused


def _run(pattern: Pattern, data: dict[str, Any]) -> list[str]:
    """Completes whatever task can start, first in net order, until none can; returns their order."""
    case = CaseNet(pattern)
    marking, _ = case.settle(case.initial, data)
    done: list[str] = []
    while case.startable(marking) and len(done) < 20:
        task = case.startable(marking)[0]
        marking = case.complete(case.start(marking, task), task)
        marking, _ = case.settle(marking, data)
        done.append(task)
    assert case.is_final(marking), (done, marking)
    return done


def _transition(pattern: Pattern, transition_id: str) -> Any:
    found = pattern.transition(transition_id)
    assert found is not None, transition_id
    return found


SUB = bpmn(
    '<startEvent id="s"/><task id="a" name="Prepare"/>'
    '<subProcess id="sub" name="Assemble"><startEvent id="ss"/><task id="b" name="Screw"/>'
    '<endEvent id="se"/>' + flows("g1: ss -> b", "g2: b -> se") + "</subProcess>"
    '<task id="c" name="Inspect"/><endEvent id="e"/>'
    + flows("f1: s -> a", "f2: a -> sub", "f3: sub -> c", "f4: c -> e")
)


def test_a_sub_process_is_flattened_between_labelled_steps_and_runs() -> None:
    pattern = bpmn_to_pattern(SUB)
    labels = {t.label for p in pattern.processes for t in p.transitions}
    assert {"Assemble: begins", "Assemble: ends"} <= labels
    assert _run(pattern, {}) == ["a", "b", "c"]
    assert check_pattern(pattern).sound is True


def test_a_call_activity_inlines_the_process_it_calls_and_that_process_is_not_imported_alone() -> (
    None
):
    text = f"""<definitions xmlns="{BPMN_NAMESPACE}" id="d" targetNamespace="urn:t">
      <process id="Main"><startEvent id="s"/><callActivity id="call" name="Check" calledElement="Sub"/>
        <endEvent id="e"/>{flows("f1: s -> call", "f2: call -> e")}</process>
      <process id="Sub"><startEvent id="s2"/><task id="t" name="Look"/><endEvent id="e2"/>
        {flows("g1: s2 -> t", "g2: t -> e2")}</process>
    </definitions>"""
    pattern = bpmn_to_pattern(text)
    assert [p.id for p in pattern.processes] == ["Main"]
    assert _run(pattern, {}) == ["call.t"]


def test_a_juel_condition_becomes_a_guard_that_routes_the_case() -> None:
    text = bpmn(
        '<startEvent id="s"/><exclusiveGateway id="x" default="low"/><task id="big"/><task id="small"/>'
        '<exclusiveGateway id="m"/><endEvent id="e"/>'
        '<sequenceFlow id="high" sourceRef="x" targetRef="big">'
        "<conditionExpression>${amount &gt; 1000 &amp;&amp; !blocked}</conditionExpression>"
        "</sequenceFlow>"
        + flows("f1: s -> x", "low: x -> small", "f2: big -> m", "f3: small -> m", "f4: m -> e")
    )
    pattern = bpmn_to_pattern(text)
    assert (
        _transition(pattern, "x_high").extra["guard"] == "data.amount > 1000 and not data.blocked"
    )
    assert _run(pattern, {"amount": 5000, "blocked": False}) == ["big"]
    assert _run(pattern, {"amount": 5, "blocked": False}) == ["small"]


def test_an_empty_condition_is_none_and_prose_is_left_to_rewrite() -> None:
    text = bpmn(
        '<startEvent id="s"/><task id="a"/><exclusiveGateway id="x"/><task id="b"/><endEvent id="e"/>'
        '<sequenceFlow id="f1" sourceRef="s" targetRef="a"><conditionExpression/></sequenceFlow>'
        '<sequenceFlow id="f3" sourceRef="x" targetRef="b">'
        "<conditionExpression>Amount over 1000 €</conditionExpression></sequenceFlow>"
        + flows("f2: a -> x", "f4: b -> e")
    )
    pattern = bpmn_to_pattern(text)
    step = _transition(pattern, "x_f3")
    assert "guard" not in step.extra
    assert "Amount over 1000 €" in step.extra["rewrite"]


def test_a_timer_boundary_event_waits_its_duration_and_cancels_the_task() -> None:
    text = bpmn(
        '<startEvent id="s"/><task id="a" name="Wait for part"/><endEvent id="e"/>'
        '<boundaryEvent id="late" name="Too late" attachedToRef="a"><timerEventDefinition>'
        "<timeDuration>PT5M</timeDuration></timerEventDefinition></boundaryEvent>"
        '<task id="alarm"/><endEvent id="e2"/>'
        + flows("f1: s -> a", "f2: a -> e", "f3: late -> alarm", "f4: alarm -> e2")
    )
    pattern = bpmn_to_pattern(text)
    late = _transition(pattern, "late")
    assert late.extra["timer"] == "PT5M"
    assert "a" in late.extra["cancels"]


def test_a_message_flow_between_pools_sends_from_one_and_is_awaited_by_the_other() -> None:
    text = f"""<definitions xmlns="{BPMN_NAMESPACE}" id="d" targetNamespace="urn:t">
      <message id="m1" name="part ready"/>
      <collaboration id="c"><participant id="p1" name="Cobot" processRef="A"/>
        <participant id="p2" name="Operator" processRef="B"/>
        <messageFlow id="mf" sourceRef="pick" targetRef="wait"/></collaboration>
      <process id="A"><startEvent id="s"/><task id="pick"/><endEvent id="e"/>
        {flows("f1: s -> pick", "f2: pick -> e")}</process>
      <process id="B"><startEvent id="s2"/><intermediateCatchEvent id="wait">
        <messageEventDefinition messageRef="m1"/></intermediateCatchEvent>
        <task id="mount"/><endEvent id="e2"/>
        {flows("g1: s2 -> wait", "g2: wait -> mount", "g3: mount -> e2")}</process>
    </definitions>"""
    pattern = bpmn_to_pattern(text)
    assert _transition(pattern, "pick").extra["send"] == {
        "name": "part ready",
        "correlation": {"case": "=case.id"},
    }
    assert _transition(pattern, "wait").extra["message"] == {
        "name": "part ready",
        "correlation": {"case": "case.id"},
    }


def test_a_terminate_end_event_cancels_the_rest_of_its_process() -> None:
    text = bpmn(
        '<startEvent id="s"/><parallelGateway id="fork"/><task id="a"/><task id="b"/>'
        '<endEvent id="stop"><terminateEventDefinition/></endEvent><endEvent id="e"/>'
        + flows("f1: s -> fork", "f2: fork -> a", "f3: fork -> b", "f4: a -> stop", "f5: b -> e")
    )
    pattern = bpmn_to_pattern(text)
    ending = next(t for p in pattern.processes for t in p.transitions if "cancels" in t.extra)
    assert {"b", "f5"} <= set(ending.extra["cancels"])


def test_an_inclusive_block_gets_a_step_per_subset_and_a_join_that_waits_for_it() -> None:
    text = bpmn(
        '<startEvent id="s"/><inclusiveGateway id="or"/><task id="a"/><task id="b"/>'
        '<inclusiveGateway id="join"/><endEvent id="e"/>'
        + flows("f1: s -> or", "f2: or -> a", "f3: or -> b", "f4: a -> join", "f5: b -> join")
        + flows("f6: join -> e")
    )
    pattern = bpmn_to_pattern(text)
    splits = [t for p in pattern.processes for t in p.transitions if t.id.startswith("or_")]
    assert len(splits) == 3
    assert check_pattern(pattern).sound is True


def test_a_refused_element_is_named_once_by_name_and_id_and_its_flows_say_nothing() -> None:
    error = refused(
        bpmn(
            '<startEvent id="s"/><complexGateway id="cx" name="Two of three"/><endEvent id="e"/>'
            + flows("f1: s -> cx", "f2: cx -> e")
        )
    )
    assert [i.message for i in error.issues] == [
        'The complex gateway "Two of three" (cx) cannot be imported: a complex gateway\'s '
        "activation rule has no Petri net mapping in hrc."
    ]
    assert "hrc-pattern" not in str(FormatError(error.issues))


def test_elements_inside_a_sub_process_are_inspected_too() -> None:
    error = refused(
        bpmn(
            '<startEvent id="s"/><subProcess id="sub"><startEvent id="ss"/>'
            '<complexGateway id="deep" name="Inner"/>' + flows("g1: ss -> deep") + "</subProcess>"
            '<endEvent id="e"/>' + flows("f1: s -> sub", "f2: sub -> e")
        )
    )
    assert any("deep" in i.elements and '"Inner"' in i.message for i in error.issues)
