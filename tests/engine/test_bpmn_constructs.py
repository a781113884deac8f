"""BPMN constructs of real models: sub-processes, call activities, events, gateways, conditions.

Each test imports a small hand-written snippet and runs or checks the net it
becomes, so the mapping's behaviour is asserted, not just its shape.
"""

from typing import Any

from hrc.engine.bpmn import BPMN_NAMESPACE, bpmn_to_pattern
from hrc.engine.check import check_pattern
from hrc.engine.document import FormatError, read_pattern
from hrc.engine.model import Pattern
from hrc.engine.runtime import CaseNet, apply_outputs
from tests.engine.builders import document, process
from tests.engine.test_bpmn import _arcs, bpmn, flows, refused


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


SIMPLE_FLOW = '<startEvent id="s"/><task id="a"/><endEvent id="e"/>' + flows(
    "f1: s -> a", "f2: a -> e"
)

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


def test_an_xpath_condition_over_data_objects_becomes_a_guard_that_routes_the_case() -> None:
    xpath = 'language="http://www.w3.org/1999/XPath"'
    text = bpmn(
        '<startEvent id="s"/><exclusiveGateway id="x"/><task id="pay"/><task id="review"/>'
        '<exclusiveGateway id="m"/><endEvent id="e"/>'
        '<sequenceFlow id="yes" sourceRef="x" targetRef="pay">'
        "<conditionExpression>bpmn:getDataObject('approved')</conditionExpression></sequenceFlow>"
        '<sequenceFlow id="no" sourceRef="x" targetRef="review">'
        f"<conditionExpression {xpath}>not(bpmn:getDataObject('approved')) and "
        "bpmn:getDataObject('state') = 'open'</conditionExpression></sequenceFlow>"
        '<sequenceFlow id="f2" sourceRef="pay" targetRef="m">'
        f"<conditionExpression {xpath}>true()</conditionExpression></sequenceFlow>"
        + flows("f1: s -> x", "f3: review -> m", "f4: m -> e")
    )
    pattern = bpmn_to_pattern(text)
    assert _transition(pattern, "x_yes").extra["guard"] == "data.approved"
    assert _transition(pattern, "x_no").extra["guard"] == (
        "not ( data.approved ) and data.state == 'open'"
    )
    assert _run(pattern, {"approved": True, "state": "open"}) == ["pay"]
    assert _run(pattern, {"approved": False, "state": "open"}) == ["review"]


def test_a_task_that_writes_the_data_a_condition_reads_asks_for_it_in_its_form() -> None:
    text = bpmn(
        '<startEvent id="s"/><userTask id="check" name="Check">'
        '<ioSpecification><dataOutput id="o1" name="approved"/></ioSpecification>'
        "<dataOutputAssociation><targetRef>ref</targetRef></dataOutputAssociation></userTask>"
        '<dataObject id="obj" name="verdict"/><dataObjectReference id="ref" dataObjectRef="obj"'
        ' name="verdict"/>'
        '<exclusiveGateway id="x"/><task id="pay"/><task id="ask"/><task id="drop"/>'
        '<exclusiveGateway id="m"/><endEvent id="e"/>'
        '<sequenceFlow id="yes" sourceRef="x" targetRef="pay"><conditionExpression>'
        "${approved}</conditionExpression></sequenceFlow>"
        '<sequenceFlow id="more" sourceRef="x" targetRef="ask"><conditionExpression>'
        "${!approved &amp;&amp; verdict == 'unclear'}</conditionExpression></sequenceFlow>"
        '<sequenceFlow id="no" sourceRef="x" targetRef="drop"><conditionExpression>'
        "${!approved &amp;&amp; verdict == 'wrong'}</conditionExpression></sequenceFlow>"
        + flows("f1: s -> check", "f2: check -> x", "f3: pay -> m", "f4: ask -> m")
        + flows("f5: drop -> m", "f6: m -> e")
    )
    pattern = bpmn_to_pattern(text)
    config = _transition(pattern, "check").extra["task"]

    assert config["form"] == {
        "type": "object",
        "properties": {
            "approved": {"type": "boolean"},
            "verdict": {"type": "string", "enum": ["unclear", "wrong"]},
        },
        "required": ["approved", "verdict"],
    }
    assert config["outputs"] == {"approved": "result.approved", "verdict": "result.verdict"}
    assert "task" not in _transition(pattern, "pay").extra
    case = CaseNet(pattern)
    data = case.initial_data()
    marking, _ = case.settle(case.initial, data)
    marking = case.start(marking, "check")
    data = apply_outputs(
        case.tasks["check"], "check", {"approved": False, "verdict": "wrong"}, data
    )
    marking, _ = case.settle(case.complete(marking, "check"), data)
    assert case.startable(marking) == ["drop"]


def test_an_xpath_path_or_function_is_left_to_rewrite() -> None:
    text = bpmn(
        '<startEvent id="s"/><exclusiveGateway id="x"/><task id="b"/><endEvent id="e"/>'
        '<sequenceFlow id="f2" sourceRef="x" targetRef="b"><conditionExpression '
        'language="http://www.w3.org/1999/XPath">count(/order/item) &gt; 3</conditionExpression>'
        "</sequenceFlow>" + flows("f1: s -> x", "f3: b -> e")
    )
    step = _transition(bpmn_to_pattern(text), "x_f2")
    assert "guard" not in step.extra
    assert "count(/order/item)" in step.extra["rewrite"]


def test_a_choice_without_conditions_takes_the_branch_nearest_an_end_first() -> None:
    # "Retry?" drawn with its way back first: taken first in net order, the case never ended.
    text = bpmn(
        '<startEvent id="s"/><exclusiveGateway id="m"/><task id="pay" name="Pay"/>'
        '<exclusiveGateway id="retry" name="Retry?"/><task id="give_up" name="Give up"/>'
        '<endEvent id="e"/>'
        + flows(
            "f1: s -> m",
            "f2: m -> pay",
            "f3: pay -> retry",
            "again: retry -> m",
            "stop: retry -> give_up",
            "f4: give_up -> e",
        )
    )
    pattern = bpmn_to_pattern(text)
    assert _run(pattern, {}) == ["pay", "give_up"]
    assert check_pattern(pattern).sound is True  # the way back is still there


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


SPOT_TAPE = read_pattern(
    document(
        process("N", "p1 tc1 p2 to1 p3", performers={"tc1": "c1", "to1": "o1"}),
        constraints=[("tc1", "to1", "time")],
    )
)


def _calling(called_element: str) -> str:
    return bpmn(
        f'<startEvent id="s"/><callActivity id="tape" name="Tape" calledElement="{called_element}"/>'
        '<endEvent id="e"/>' + flows("f1: s -> tape", "f2: tape -> e")
    )


def test_a_call_activity_inlines_the_published_pattern_it_names_with_its_actors() -> None:
    asked: list[list[str]] = []

    def published(names: list[str]) -> Pattern | None:
        asked.append(names)
        return SPOT_TAPE if "SpotTape" in names else None

    pattern = bpmn_to_pattern(_calling("SpotTape"), published)
    assert asked == [["SpotTape", "Tape"]]
    assert _run(pattern, {}) == ["tape.tc1", "tape.to1"]
    assert {(a.id, a.type) for a in pattern.actors} == {
        ("tape.c1", "cobot"),
        ("tape.o1", "operator"),
    }
    assert [(c.source, c.target) for c in pattern.constraints] == [("tape.tc1", "tape.to1")]


def test_a_call_activity_nothing_resolves_is_refused_naming_what_it_calls() -> None:
    error = refused(_calling("SpotTape"))
    assert [i.message for i in error.issues] == [
        "The call activity \"Tape\" (tape) calls 'SpotTape', which is neither a process of this "
        "file nor a published pattern of that name."
    ]


def test_an_event_based_gateway_lets_the_first_event_take_the_branch() -> None:
    text = bpmn(
        '<startEvent id="s"/><eventBasedGateway id="race"/>'
        '<intermediateCatchEvent id="ok"><messageEventDefinition/></intermediateCatchEvent>'
        '<intermediateCatchEvent id="late"><timerEventDefinition><timeDuration>PT1H'
        "</timeDuration></timerEventDefinition></intermediateCatchEvent>"
        '<task id="a"/><task id="b"/><endEvent id="e"/><endEvent id="e2"/>'
        + flows("f1: s -> race", "f2: race -> ok", "f3: race -> late", "f4: ok -> a")
        + flows("f5: late -> b", "f6: a -> e", "f7: b -> e2")
    )
    pattern = bpmn_to_pattern(text)
    process = pattern.processes[0]
    racing = {t for p, t in process.arcs if p == "f1"}
    assert racing == {"ok", "late"}
    assert _transition(pattern, "late").extra["timer"] == "PT1H"
    assert _transition(pattern, "ok").extra["message"]["name"] == "ok"


def test_an_error_end_inside_a_sub_process_leaves_through_the_boundary_that_catches_it() -> None:
    text = bpmn(
        '<startEvent id="s"/><subProcess id="sub" name="Mount"><startEvent id="ss"/>'
        '<task id="m"/><exclusiveGateway id="x"/><endEvent id="ok"/>'
        '<endEvent id="fail"><errorEventDefinition errorRef="broken"/></endEvent>'
        + flows("g1: ss -> m", "g2: m -> x", "g3: x -> ok", "g4: x -> fail")
        + "</subProcess>"
        '<boundaryEvent id="catch" attachedToRef="sub"><errorEventDefinition errorRef="broken"/>'
        '</boundaryEvent><task id="scrap"/><task id="ship"/><endEvent id="e"/><endEvent id="e2"/>'
        + flows("f1: s -> sub", "f2: sub -> ship", "f3: ship -> e", "f4: catch -> scrap")
        + flows("f5: scrap -> e2"),
        outside='<error id="broken" name="Part broken"/>',
    )
    pattern = bpmn_to_pattern(text)
    thrown = next(t for p in pattern.processes for t in p.transitions if t.id.startswith("fail"))
    arcs = _arcs(pattern)
    assert (thrown.id, "f4") in arcs
    assert ("sub_scope", thrown.id) in arcs
    assert pattern.transition("catch") is None  # only the error end throws to it
    assert "m" in thrown.extra["cancels"]


def test_a_non_interrupting_boundary_event_fires_at_most_once_and_keeps_the_task() -> None:
    text = bpmn(
        '<startEvent id="s"/><task id="a"/><endEvent id="e"/>'
        '<boundaryEvent id="remind" attachedToRef="a" cancelActivity="false">'
        "<timerEventDefinition><timeDuration>PT10M</timeDuration></timerEventDefinition>"
        '</boundaryEvent><task id="call"/><endEvent id="e2"/>'
        + flows("f1: s -> a", "f2: a -> e", "f3: remind -> call", "f4: call -> e2")
    )
    pattern = bpmn_to_pattern(text)
    remind = _transition(pattern, "remind")
    arcs = _arcs(pattern)
    assert {("remind_armed", "remind"), ("a_scope", "remind"), ("remind", "a_scope")} <= arcs
    assert "cancels" not in remind.extra
    ends = next(t for p in pattern.processes for t in p.transitions if t.label == "a: ends")
    assert ends.extra["cancels"] == ["remind_armed"]


def test_multi_instance_with_a_literal_count_makes_copies_and_others_are_to_rewrite() -> None:
    text = bpmn(
        '<startEvent id="s"/><task id="a" name="Screw"><multiInstanceLoopCharacteristics>'
        "<loopCardinality>3</loopCardinality></multiInstanceLoopCharacteristics></task>"
        '<task id="b"><multiInstanceLoopCharacteristics isSequential="true">'
        "<loopCardinality>${n}</loopCardinality></multiInstanceLoopCharacteristics></task>"
        '<endEvent id="e"/>' + flows("f1: s -> a", "f2: a -> b", "f3: b -> e")
    )
    pattern = bpmn_to_pattern(text)
    assert _run(pattern, {}) == ["a", "a_2", "a_3", "b"]
    assert _transition(pattern, "a_3").label == "Screw (3 of 3)"
    assert "${n}" in _transition(pattern, "b").extra["rewrite"]


def test_a_standard_loop_repeats_the_task_while_its_condition_holds() -> None:
    text = bpmn(
        '<startEvent id="s"/><task id="a"><standardLoopCharacteristics>'
        "<loopCondition>${tries &lt; 3}</loopCondition></standardLoopCharacteristics></task>"
        '<endEvent id="e"/>' + flows("f1: s -> a", "f2: a -> e")
    )
    pattern = bpmn_to_pattern(text)
    again = next(t for p in pattern.processes for t in p.transitions if t.id.startswith("a_again"))
    assert again.extra == {"guard": "data.tries < 3"}
    assert _run(pattern, {"tries": 5}) == ["a"]


def test_a_link_event_jumps_to_the_catch_event_of_the_same_name() -> None:
    text = bpmn(
        '<startEvent id="s"/><task id="a"/><intermediateThrowEvent id="go">'
        '<linkEventDefinition name="L"/></intermediateThrowEvent>'
        '<intermediateCatchEvent id="land"><linkEventDefinition name="L"/></intermediateCatchEvent>'
        '<task id="b"/><endEvent id="e"/>'
        + flows("f1: s -> a", "f2: a -> go", "f3: land -> b", "f4: b -> e")
    )
    assert _run(bpmn_to_pattern(text), {}) == ["a", "b"]


def test_a_task_with_a_default_flow_chooses_between_its_flows() -> None:
    text = bpmn(
        '<startEvent id="s"/><task id="a" default="other"/><task id="b"/><task id="c"/>'
        '<exclusiveGateway id="m"/><endEvent id="e"/>'
        '<sequenceFlow id="main" sourceRef="a" targetRef="b"><conditionExpression>'
        "${ok}</conditionExpression></sequenceFlow>"
        + flows("f1: s -> a", "other: a -> c", "f2: b -> m", "f3: c -> m", "f4: m -> e")
    )
    pattern = bpmn_to_pattern(text)
    assert _run(pattern, {"ok": True}) == ["a", "b"]
    assert _run(pattern, {"ok": False}) == ["a", "c"]


def test_a_shared_event_definition_at_the_root_is_read_there() -> None:
    text = bpmn(
        '<startEvent id="s"/><intermediateCatchEvent id="wait"><eventDefinitionRef>tick'
        '</eventDefinitionRef></intermediateCatchEvent><endEvent id="e"/>'
        + flows("f1: s -> wait", "f2: wait -> e"),
        outside='<timerEventDefinition id="tick"><timeDuration>PT30S</timeDuration>'
        "</timerEventDefinition>",
    )
    assert _transition(bpmn_to_pattern(text), "wait").extra["timer"] == "PT30S"


def test_an_interrupting_event_sub_process_is_a_boundary_event_on_its_process() -> None:
    text = bpmn(
        '<startEvent id="s"/><task id="a"/><endEvent id="e"/>'
        + flows("f1: s -> a", "f2: a -> e")
        + '<subProcess id="stop" name="Emergency stop" triggeredByEvent="true">'
        '<startEvent id="alarm" name="Alarm"><messageEventDefinition/></startEvent>'
        '<task id="secure"/><endEvent id="se"/>'
        + flows("g1: alarm -> secure", "g2: secure -> se")
        + "</subProcess>"
    )
    pattern = bpmn_to_pattern(text)
    trigger = next(t for p in pattern.processes for t in p.transitions if t.label == "Alarm")
    assert trigger.extra["message"]["name"] == "Alarm"
    assert "a" in trigger.extra["cancels"]
    assert ("P_running", trigger.id) in _arcs(pattern)
    ending = _transition(pattern, "e_end")
    assert ending.extra["cancels"] == ["P_running"]  # the process' end closes the window


def test_a_non_interrupting_event_sub_process_is_refused_saying_why() -> None:
    error = refused(
        bpmn(
            SIMPLE_FLOW + '<subProcess id="esp" name="Log" triggeredByEvent="true">'
            '<startEvent id="t" isInterrupting="false"><messageEventDefinition/></startEvent>'
            "</subProcess>"
        )
    )
    assert [i.elements for i in error.issues] == [("esp",)]
    assert 'event sub-process "Log" (esp)' in error.issues[0].message
    assert "does not interrupt" in error.issues[0].message


def test_a_compensation_handler_is_refused_naming_the_activity_it_undoes() -> None:
    error = refused(
        bpmn(
            '<startEvent id="s"/><task id="book" name="Book hotel"/><endEvent id="e"/>'
            + flows("f1: s -> book", "f2: book -> e")
            + '<boundaryEvent id="comp" attachedToRef="book"><compensateEventDefinition/>'
            '</boundaryEvent><task id="cancel" name="Cancel hotel" isForCompensation="true"/>'
            '<association id="as" sourceRef="comp" targetRef="cancel"/>'
        )
    )
    messages = [i.message for i in error.issues]
    assert any(
        m.startswith('The task "Cancel hotel" (cancel) compensates task "Book hotel" (book)')
        for m in messages
    ), messages


def test_tasks_inlined_from_a_called_process_keep_the_lanes_they_have_there() -> None:
    text = f"""<definitions xmlns="{BPMN_NAMESPACE}" id="d" targetNamespace="urn:t">
      <process id="Main"><laneSet id="ls1"><lane id="op" name="Operator">
        <flowNodeRef>call</flowNodeRef></lane></laneSet>
        <startEvent id="s"/><callActivity id="call" calledElement="Sub"/><endEvent id="e"/>
        {flows("f1: s -> call", "f2: call -> e")}</process>
      <process id="Sub"><laneSet id="ls2"><lane id="robot" name="Cobot">
        <flowNodeRef>weld</flowNodeRef></lane></laneSet>
        <startEvent id="s2"/><task id="weld"/><task id="check"/><endEvent id="e2"/>
        {flows("g1: s2 -> weld", "g2: weld -> check", "g3: check -> e2")}</process>
    </definitions>"""
    pattern = bpmn_to_pattern(text)
    assert _transition(pattern, "call.weld").performer == "robot"
    assert _transition(pattern, "call.check").performer == "op"


def test_every_message_flow_into_one_receiver_carries_the_name_it_awaits() -> None:
    text = f"""<definitions xmlns="{BPMN_NAMESPACE}" id="d" targetNamespace="urn:t">
      <collaboration id="c"><participant id="p1" processRef="A"/>
        <participant id="p2" processRef="B"/>
        <messageFlow id="m1" name="ready" sourceRef="a1" targetRef="wait"/>
        <messageFlow id="m2" name="also ready" sourceRef="a2" targetRef="wait"/></collaboration>
      <process id="A"><startEvent id="s"/><task id="a1"/><task id="a2"/><endEvent id="e"/>
        {flows("f1: s -> a1", "f2: a1 -> a2", "f3: a2 -> e")}</process>
      <process id="B"><startEvent id="s2"/><intermediateCatchEvent id="wait">
        <messageEventDefinition/></intermediateCatchEvent><endEvent id="e2"/>
        {flows("g1: s2 -> wait", "g2: wait -> e2")}</process>
    </definitions>"""
    pattern = bpmn_to_pattern(text)
    awaited = _transition(pattern, "wait").extra["message"]["name"]
    assert awaited == "ready"
    assert {_transition(pattern, t).extra["send"]["name"] for t in ("a1", "a2")} == {awaited}


def test_a_looping_sub_process_goes_back_from_its_end_to_its_beginning() -> None:
    text = bpmn(
        '<startEvent id="s"/><subProcess id="sub" name="Polish"><standardLoopCharacteristics>'
        "<loopCondition>${rough}</loopCondition></standardLoopCharacteristics>"
        '<startEvent id="ss"/><task id="p"/><endEvent id="se"/>'
        + flows("g1: ss -> p", "g2: p -> se")
        + '</subProcess><endEvent id="e"/>'
        + flows("f1: s -> sub", "f2: sub -> e")
    )
    pattern = bpmn_to_pattern(text)
    again = next(t for p in pattern.processes for t in p.transitions if t.label == "Polish: again")
    assert again.extra == {"guard": "data.rough"}
    assert _run(pattern, {"rough": False}) == ["p"]
    assert check_pattern(pattern).sound is True


def test_a_broken_hrc_extra_is_reported_once_naming_the_element() -> None:
    error = refused(
        bpmn(
            '<startEvent id="s"/><task id="a" name="Pick"><extensionElements><hrc:extra>{no'
            '</hrc:extra></extensionElements></task><endEvent id="e"/>'
            + flows("f1: s -> a", "f2: a -> e")
        )
    )
    assert [i.message for i in error.issues] == [
        'The hrc:extra of the task "Pick" (a) is not JSON.'
    ]


def test_only_a_receive_task_waits_for_the_message_flow_that_reaches_it() -> None:
    text = f"""<definitions xmlns="{BPMN_NAMESPACE}" id="d" targetNamespace="urn:t">
      <collaboration id="c"><participant id="p1" processRef="A"/>
        <participant id="p2" processRef="B"/>
        <messageFlow id="m1" name="go" sourceRef="a" targetRef="wait"/>
        <messageFlow id="m2" name="fyi" sourceRef="a" targetRef="work"/></collaboration>
      <process id="A"><startEvent id="s"/><task id="a"/><endEvent id="e"/>
        {flows("f1: s -> a", "f2: a -> e")}</process>
      <process id="B"><startEvent id="s2"/><receiveTask id="wait" name="Wait"/>
        <userTask id="work"/><endEvent id="e2"/>
        {flows("g1: s2 -> wait", "g2: wait -> work", "g3: work -> e2")}</process>
    </definitions>"""
    pattern = bpmn_to_pattern(text)
    step = next(t for p in pattern.processes for t in p.transitions if t.label == "Wait: message")
    assert step.extra["message"]["name"] == "go"
    assert not any(
        "work" in t.id and "message" in t.extra for p in pattern.processes for t in p.transitions
    )


def test_a_recursive_call_is_refused_naming_the_call_activity() -> None:
    text = f"""<definitions xmlns="{BPMN_NAMESPACE}" id="d" targetNamespace="urn:t">
      <process id="Main"><startEvent id="s"/><callActivity id="call" calledElement="Sub"/>
        <endEvent id="e"/>{flows("f1: s -> call", "f2: call -> e")}</process>
      <process id="Sub"><startEvent id="s2"/><callActivity id="again" name="Again"
        calledElement="Sub"/><endEvent id="e2"/>{flows("g1: s2 -> again", "g2: again -> e2")}
      </process>
    </definitions>"""
    error = refused(text)
    assert [i.elements for i in error.issues] == [("again",)]
    assert 'call activity "Again" (again) calls process Sub' in error.issues[0].message


def test_variables_of_translated_conditions_become_case_data_with_defaults() -> None:
    text = bpmn(
        '<startEvent id="s"/><exclusiveGateway id="x" default="low"/><task id="big"/>'
        '<task id="small"/><exclusiveGateway id="m"/><endEvent id="e"/>'
        '<sequenceFlow id="high" sourceRef="x" targetRef="big">'
        "<conditionExpression>${amount &gt; 1000 &amp;&amp; region == 'EU' &amp;&amp; !blocked}"
        "</conditionExpression></sequenceFlow>"
        + flows("f1: s -> x", "low: x -> small", "f2: big -> m", "f3: small -> m", "f4: m -> e")
    )
    pattern = bpmn_to_pattern(text)
    assert pattern.extra["data"] == {"amount": 0, "region": "", "blocked": False}
    assert _run(pattern, CaseNet(pattern).initial_data()) == ["small"]


def test_a_receive_task_after_an_event_based_gateway_races_for_the_same_place() -> None:
    text = f"""<definitions xmlns="{BPMN_NAMESPACE}" id="d" targetNamespace="urn:t">
      <collaboration id="c"><participant id="p1" processRef="A"/>
        <participant id="p2" processRef="B"/>
        <messageFlow id="m1" name="order" sourceRef="a" targetRef="take"/></collaboration>
      <process id="A"><startEvent id="s"/><task id="a"/><endEvent id="e"/>
        {flows("f1: s -> a", "f2: a -> e")}</process>
      <process id="B"><startEvent id="s2"/><eventBasedGateway id="race"/>
        <receiveTask id="take" name="Take order"/>
        <intermediateCatchEvent id="idle"><timerEventDefinition><timeDuration>PT1H</timeDuration>
        </timerEventDefinition></intermediateCatchEvent><endEvent id="e2"/><endEvent id="e3"/>
        {flows("g1: s2 -> race", "g2: race -> take", "g3: race -> idle", "g4: take -> e2")}
        {flows("g5: idle -> e3")}</process>
    </definitions>"""
    pattern = bpmn_to_pattern(text)
    racing = {t for p in pattern.processes for s, t in p.arcs if s == "g1"}
    assert racing == {"idle", "take_receive"}


def test_a_receive_task_with_a_boundary_event_waits_for_its_message_inside_its_scope() -> None:
    text = bpmn(
        '<startEvent id="s"/><receiveTask id="take" name="Take part" messageRef="m"/>'
        '<endEvent id="e"/><boundaryEvent id="late" attachedToRef="take"><timerEventDefinition>'
        "<timeDuration>PT5M</timeDuration></timerEventDefinition></boundaryEvent>"
        '<endEvent id="e2"/>' + flows("f1: s -> take", "f2: take -> e", "f3: late -> e2"),
        outside='<message id="m" name="part"/>',
    )
    pattern = bpmn_to_pattern(text)
    assert _transition(pattern, "take_receive").extra["message"]["name"] == "part"
    assert {("take_start", "take_receive"), ("take_receive", "take_received")} <= _arcs(pattern)
    assert ("take_start", "take") not in _arcs(pattern)
    assert not [e for e in check_pattern(pattern).errors if e.code == "not-workflow-net"]


def test_a_node_no_flow_enters_beside_a_start_event_is_never_started_and_found_dead() -> None:
    # As in Bonita's export of MIWG C.1.0, which lost the flow into a gateway.
    pattern = bpmn_to_pattern(
        bpmn(
            '<startEvent id="s"/><task id="a" name="Approve"/><endEvent id="e"/>'
            '<exclusiveGateway id="g" name="Review successful"/><task id="b" name="Pay"/>'
            + flows("f1: s -> a", "f2: a -> e", "f3: g -> b", "f4: b -> e")
        )
    )
    assert _run(pattern, {}) == ["a"]
    report = check_pattern(pattern)
    assert [issue.code for issue in report.errors] == ["unsound"]
    assert "never" in report.errors[0].message
    assert "Pay" in report.errors[0].message
