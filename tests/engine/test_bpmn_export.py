"""BPMN export that other tools read: OMG's XSD accepts it, and hrc's importer gives it back.

The schema is OMG's BPMN 2.0 XSD (BPMN20.xsd with Semantic.xsd, BPMNDI.xsd,
DC.xsd and DI.xsd), as SpiffWorkflow ships it. The exports checked are the
example library, the use cases, the shared examples beside the checkout, and a
model with the keys of timers, cancellation, messages between pools and
guards.

Round trip: an export imports back as the same document, every key, id, order
and position included (`bpmn_marks`). Edited in another tool (a task added,
its marks missing), a process is read by BPMN's mapping instead, which keeps
the edit; the mapping alone, with every mark removed, gives back each task and
each silent transition that carries configuration (timer, cancels, message,
send, guard, rewrite) with its id, performer, label and keys, and what
`cancels` names is still there.
"""

import itertools
import json
from functools import cache
from importlib.resources import files
from pathlib import Path
from typing import Any

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from lxml import etree

from hrc.engine.bpmn import BPMN_NAMESPACE, HRC_NAMESPACE, bpmn_to_pattern
from hrc.engine.bpmn_export import pattern_to_bpmn
from hrc.engine.check import check_pattern
from hrc.engine.document import read_pattern, write_pattern
from hrc.engine.layout import lay_out_pattern
from hrc.engine.model import Pattern, Process
from tests.engine.builders import EXAMPLES, document, process
from tests.engine.strategies import cancelling, decorated, patterns

ROOT = Path(__file__).resolve().parents[2]
# Beside the checkout in CI (../shared); a worktree sits one level deeper.
SHARED = next((p / "shared" for p in ROOT.parents if (p / "shared").is_dir()), ROOT / "shared")
LIBRARY = sorted(EXAMPLES.rglob("*.json")) + sorted((SHARED / "examples").glob("*.json"))


def _name(path: Path) -> str:
    return f"{path.parent.name}/{path.stem}"


def configured() -> dict[str, Any]:
    """Two pools: the operator's load sends a message the cobot's process waits for, against a timer.

    The operator's inspection loops back on a guard, and a watchdog timer cancels
    the inspection and its places; a time and a space constraint tie the pools.
    """
    operator = process(
        "cell_operator",
        "ps load pa inspect pb x_ok pe",
        "pb x_rework pa",
        "load pw x_watchdog pe",
        performers={"load": "o1", "inspect": "o1"},
        workpiece="part",
    )
    cobot = process(
        "cell_cobot",
        "pc0 x_loaded pc1 grasp pc2 drop pc3",
        "pc0 x_give_up pc3",
        performers={"grasp": "c1", "drop": "c1"},
        workpiece="part",
    )
    operator["arcs"].append(["pw", "x_ok"])  # the inspection ends the watch
    keys = {
        "load": {"send": {"name": "loaded", "correlation": {"case": "=case.id"}}},
        "x_ok": {"guard": "data.ok"},
        "x_rework": {"guard": "not data.ok", "rewrite": "the original said ${!ok} in JUEL"},
        "x_watchdog": {"timer": "PT10M", "cancels": ["inspect", "pa", "pb"]},
        "x_loaded": {"message": {"name": "loaded", "correlation": {"case": "case.id"}}},
        "x_give_up": {"timer": "PT5M", "label": "no part"},
    }
    for net in (operator, cobot):
        for transition in net["transitions"]:
            transition.update(keys.get(transition["id"], {}))
    return document(
        operator, cobot, constraints=[("load", "grasp", "time"), ("drop", "inspect", "space")]
    )


def _library() -> list[Any]:
    examples = [pytest.param(json.loads(p.read_text()), id=_name(p)) for p in LIBRARY]
    return [*examples, pytest.param(configured(), id="timers-messages-guards")]


# The schema ------------------------------------------------------------------------------


@cache
def bpmn_schema() -> etree.XMLSchema:
    root = files("SpiffWorkflow.bpmn.parser") / "schema" / "BPMN20.xsd"
    # Parsed from its path, so the xsd:include and xsd:import beside it resolve.
    return etree.XMLSchema(etree.parse(str(root)))


def schema_errors(text: str) -> list[str]:
    schema = bpmn_schema()
    if schema.validate(etree.fromstring(text.encode())):
        return []
    return [f"line {e.line}: {e.message}" for e in schema.error_log]


@pytest.mark.parametrize("data", _library())
def test_every_export_validates_against_the_bpmn_schema(data: dict[str, Any]) -> None:
    assert schema_errors(pattern_to_bpmn(read_pattern(data))) == []


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(patterns(mutate=False) | decorated())
def test_generated_exports_validate_against_the_bpmn_schema(data: dict[str, Any]) -> None:
    assert schema_errors(pattern_to_bpmn(read_pattern(data))) == []


def test_the_shared_examples_are_found() -> None:
    assert sorted((SHARED / "examples").glob("*.json"))


def test_the_schema_refuses_what_bpmn_does_not_allow() -> None:
    """Element order matters to the XSD: a flow node after the process' artifacts is refused."""
    root = etree.fromstring(pattern_to_bpmn(read_pattern(configured())).encode())
    body = root.find(f"{{{BPMN_NAMESPACE}}}process")
    assert body is not None
    association = body.find(f"{{{BPMN_NAMESPACE}}}association")
    task = body.find(f"{{{BPMN_NAMESPACE}}}task")
    assert association is not None
    assert task is not None
    body.remove(task)
    body.append(task)
    errors = schema_errors(etree.tostring(root, encoding="unicode"))
    assert errors
    assert "task" in errors[0]


# Round trip ------------------------------------------------------------------------------


def unmarked(text: str) -> str:
    """The export without the marks that tell hrc what each element stands for, as a tool that
    drops attributes and extension elements it does not know would save it."""
    root = etree.fromstring(text.encode())
    for element in root.iter():
        element.attrib.pop(f"{{{HRC_NAMESPACE}}}net", None)
    for net in root.iter(f"{{{HRC_NAMESPACE}}}net"):
        net.getparent().remove(net)
    return str(etree.tostring(root, encoding="unicode"))


def assert_unchanged(pattern: Pattern, text: str | None = None) -> Pattern:
    back = bpmn_to_pattern(text or pattern_to_bpmn(pattern))
    assert write_pattern(back) == write_pattern(pattern)
    return back


@pytest.mark.parametrize("data", _library())
def test_every_export_imports_back_unchanged(data: dict[str, Any]) -> None:
    assert_unchanged(read_pattern(data))


def test_the_marks_are_what_brings_it_back_unchanged() -> None:
    """Without them BPMN's mapping reads the same drawing as another net: flows become places."""
    pattern = read_pattern(configured())
    back = bpmn_to_pattern(unmarked(pattern_to_bpmn(pattern)))
    assert write_pattern(back) != write_pattern(pattern)
    assert len(back.processes[0].places) > len(pattern.processes[0].places)


def _keys(extra: Any) -> dict[str, Any]:
    return {key: value for key, value in extra.items() if key != "layout"}


def _node_kinds(net: Process) -> dict[str, str]:
    return {
        **{place.id: "place" for place in net.places},
        **{transition.id: "transition" for transition in net.transitions},
    }


def assert_configuration_comes_back(pattern: Pattern, back: Pattern) -> None:
    for original, copy in zip(pattern.processes, back.processes, strict=True):
        copied = {t.id: t for t in copy.transitions}
        for transition in original.transitions:
            if not (transition.is_task or _keys(transition.extra)):
                continue  # plain routing: BPMN's gateways and events bring their own
            twin = copied.get(transition.id)
            assert twin is not None, f"{transition.id} did not come back"
            assert (twin.performer, twin.label) == (transition.performer, transition.label)
            assert _keys(twin.extra) == _keys(transition.extra), transition.id
        kinds, copied_kinds = _node_kinds(original), _node_kinds(copy)
        for transition in original.transitions:
            for named in transition.extra.get("cancels", []):
                assert copied_kinds.get(named) == kinds[named], f"{transition.id} cancels {named}"


@pytest.mark.parametrize("data", _library())
def test_every_export_without_marks_imports_back_with_its_configuration(
    data: dict[str, Any],
) -> None:
    pattern = read_pattern(data)
    back = bpmn_to_pattern(unmarked(pattern_to_bpmn(pattern)))
    assert (back.name, back.declared_pattern) == (pattern.name, pattern.declared_pattern)
    assert _keys(back.extra) == _keys(pattern.extra)
    assert back.constraints == pattern.constraints
    assert [(p.id, p.workpiece, _keys(p.extra)) for p in back.processes] == [
        (p.id, p.workpiece, _keys(p.extra)) for p in pattern.processes
    ]
    assert_configuration_comes_back(pattern, back)


@pytest.mark.parametrize("path", LIBRARY, ids=_name)
def test_every_example_without_marks_imports_back_with_its_verdict(path: Path) -> None:
    pattern = read_pattern(json.loads(path.read_text()))
    mapped = bpmn_to_pattern(unmarked(pattern_to_bpmn(pattern)))
    before, after = check_pattern(pattern), check_pattern(mapped)
    assert (after.valid, after.sound, after.patterns) == (
        before.valid,
        before.sound,
        before.patterns,
    )
    assert sorted(e.code for e in after.errors) == sorted(e.code for e in before.errors)


def test_the_configured_model_keeps_its_timers_messages_and_cancellation() -> None:
    back = bpmn_to_pattern(unmarked(pattern_to_bpmn(read_pattern(configured()))))
    watchdog, loaded = back.transition("x_watchdog"), back.transition("x_loaded")
    assert watchdog is not None
    assert loaded is not None
    assert watchdog.extra["timer"] == "PT10M"
    assert watchdog.extra["cancels"] == ["inspect", "pa", "pb"]
    assert loaded.extra["message"]["name"] == "loaded"
    assert [(c.source, c.target, c.type) for c in back.constraints] == [
        ("load", "grasp", "time"),
        ("drop", "inspect", "space"),
    ]


# The diagram -----------------------------------------------------------------------------

DI = "{http://www.omg.org/spec/BPMN/20100524/DI}"
DC = "{http://www.omg.org/spec/DD/20100524/DC}"
Box = tuple[float, float, float, float]


def _exported(data: dict[str, Any]) -> Any:
    return etree.fromstring(pattern_to_bpmn(read_pattern(data)).encode())


def _boxes(root: Any) -> dict[str, Box]:
    """bpmnElement -> (left, top, right, bottom) of its shape."""
    boxes = {}
    for shape in root.iter(f"{DI}BPMNShape"):
        bounds = shape.find(f"{DC}Bounds")
        x, y, w, h = (float(bounds.get(k)) for k in ("x", "y", "width", "height"))
        boxes[shape.get("bpmnElement")] = (x, y, x + w, y + h)
    return boxes


def _inside(box: Box, outer: Box) -> bool:
    centre_y = (box[1] + box[3]) / 2
    return outer[1] <= centre_y <= outer[3]


@pytest.mark.parametrize("data", _library())
def test_each_pool_is_drawn_apart_holding_its_lanes_and_nodes(data: dict[str, Any]) -> None:
    """Processes that share an actor share its lane in the editor; in BPMN each pool has its own."""
    root = _exported(data)
    boxes = _boxes(root)
    pools = {
        p.get("processRef"): boxes[p.get("id")]
        for p in root.iter(f"{{{BPMN_NAMESPACE}}}participant")
    }
    ordered = sorted(pools.values(), key=lambda box: box[1])
    assert all(upper[3] <= lower[1] for upper, lower in itertools.pairwise(ordered))
    for net in root.iter(f"{{{BPMN_NAMESPACE}}}process"):
        pool = pools[net.get("id")]
        for lane in net.iter(f"{{{BPMN_NAMESPACE}}}lane"):
            assert pool[1] <= boxes[lane.get("id")][1] < boxes[lane.get("id")][3] <= pool[3]
            for reference in lane.iter(f"{{{BPMN_NAMESPACE}}}flowNodeRef"):
                assert _inside(boxes[reference.text], boxes[lane.get("id")]), reference.text
        for node in net:
            if node.get("id") in boxes:
                assert _inside(boxes[node.get("id")], pool), node.get("id")


# What other tools see --------------------------------------------------------------------


def _one(root: Any, path: str) -> Any:
    found = root.xpath(path, namespaces={"bpmn": BPMN_NAMESPACE})
    assert len(found) == 1, path
    return found[0]


def test_a_timer_is_an_intermediate_timer_event_with_its_duration() -> None:
    root = _exported(configured())
    duration = _one(root, "//bpmn:intermediateCatchEvent[@id='x_give_up']//bpmn:timeDuration")
    assert duration.text == "PT5M"
    assert _one(root, "//bpmn:intermediateCatchEvent[@id='x_give_up']").get("name") == "no part"


def test_a_message_between_pools_is_a_message_flow_to_a_message_catch_event() -> None:
    root = _exported(configured())
    message = _one(root, "/bpmn:definitions/bpmn:message[@name='loaded']")
    catch = _one(root, "//bpmn:intermediateCatchEvent[@id='x_loaded']/bpmn:messageEventDefinition")
    flow = _one(root, "//bpmn:collaboration/bpmn:messageFlow")
    assert catch.get("messageRef") == message.get("id") == flow.get("messageRef")
    assert (flow.get("sourceRef"), flow.get("targetRef")) == ("load", "x_loaded")


def test_a_choice_between_a_message_and_a_timer_is_an_event_based_gateway() -> None:
    root = _exported(configured())
    gateway = _one(root, "//bpmn:eventBasedGateway")
    targets = root.xpath(
        f"//bpmn:sequenceFlow[@sourceRef='{gateway.get('id')}']/@targetRef",
        namespaces={"bpmn": BPMN_NAMESPACE},
    )
    assert sorted(targets) == ["x_give_up", "x_loaded"]
    # The operator's watchdog competes with a plain step: a data-based choice, as before.
    assert _one(root, "//bpmn:exclusiveGateway[@id='pw_split']") is not None


def test_a_silent_send_is_a_message_throw_event() -> None:
    data = configured()
    load = data["processes"][0]["transitions"][0]
    send = load.pop("send")
    data["processes"][0]["transitions"].append({"id": "x_tell", "send": send})
    data["processes"][0]["arcs"] = [
        ["x_tell", "pa"] if arc == ["load", "pa"] else arc for arc in data["processes"][0]["arcs"]
    ] + [["load", "p_told"], ["p_told", "x_tell"]]
    data["processes"][0]["places"].append({"id": "p_told"})
    root = _exported(data)
    throw = _one(root, "//bpmn:intermediateThrowEvent[@id='x_tell']/bpmn:messageEventDefinition")
    flow = _one(root, "//bpmn:collaboration/bpmn:messageFlow")
    assert (flow.get("sourceRef"), flow.get("targetRef")) == ("x_tell", "x_loaded")
    assert throw.get("messageRef") == flow.get("messageRef")
    assert schema_errors(etree.tostring(root, encoding="unicode")) == []


@st.composite
def with_events(draw: st.DrawFn) -> dict[str, Any]:
    """A generated pattern whose silent steps wait for timers or messages, or send one."""
    data = draw(patterns(mutate=False))
    keys = st.sampled_from(
        [
            {},
            {"timer": "PT1M"},
            {"message": {"name": "m", "correlation": {"case": "case.id"}}},
            {"send": {"name": "m"}},
        ]
    )
    for transition in data["processes"][0]["transitions"]:
        if "performer" not in transition:
            transition.update(draw(keys))
    return data


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(with_events())
def test_generated_exports_with_events_validate_and_import_back(data: dict[str, Any]) -> None:
    pattern = read_pattern(data)
    text = pattern_to_bpmn(pattern)
    assert schema_errors(text) == []
    assert_unchanged(pattern, text)
    assert_configuration_comes_back(pattern, bpmn_to_pattern(unmarked(text)))


# Exactly back, and edits made in other tools ---------------------------------------------

NAMES = st.text(max_size=4) | st.sampled_from([" spaced ", "line\nbreak", "o1"])


@st.composite
def awkward(draw: st.DrawFn) -> dict[str, Any]:
    """What the exporter accepts at its edges: several processes, ids XML cannot hold as ids,
    names with spaces or none at all, idle, unassigned and undeclared actors, constraints on
    silent steps in any order, and a layout on some nodes only."""
    nets = [draw(patterns()) for _ in range(draw(st.integers(1, 3)))]
    data: dict[str, Any] = {**nets[0], "name": draw(NAMES), "processes": [], "constraints": []}
    for number, net in enumerate(nets):
        prefix = draw(st.sampled_from(["", "n ", "9", "\x01", "é"])) + f"{number}_"
        body = net["processes"][0]
        rename = {node["id"]: prefix + node["id"] for node in body["places"]}
        rename |= {t["id"]: prefix + t["id"] for t in body["transitions"]}
        body["id"] = f"{prefix}N"
        body["arcs"] = [[rename[a], rename[b]] for a, b in body["arcs"]]
        for node in body["places"] + body["transitions"]:
            node["id"] = rename[node["id"]]
            if draw(st.booleans()):
                node["label" if "performer" in node else "name"] = draw(NAMES)
            if "performer" in node and draw(st.booleans()):
                node["bpmn"] = draw(st.sampled_from(["task", "userTask", "serviceTask", "?"]))
        body["actors"] = draw(st.sampled_from([body["actors"], [*body["actors"], "idle", "ghost"]]))
        del body["workpiece"]
        body.update(draw(st.fixed_dictionaries({}, optional={"name": NAMES, "workpiece": NAMES})))
        data["processes"].append(body)
        data["constraints"] += [
            {**c, "from": rename[c["from"]], "to": rename[c["to"]]} for c in net["constraints"]
        ]
        silent = [t["id"] for t in body["transitions"] if "performer" not in t]
        if silent and data["constraints"]:
            data["constraints"].append(
                {"from": silent[0], "to": data["constraints"][0]["from"], "type": "func"}
            )
    data["constraints"] = draw(st.permutations(data["constraints"]))
    actors = {a["id"]: a for net in nets for a in net["actors"]}
    actors |= {
        "idle": {"id": "idle", "type": "cobot"},
        "lonely": {"id": "lonely", "type": "operator"},
    }
    for actor in actors.values():
        if draw(st.booleans()):
            actor["name"] = draw(st.sampled_from([actor["id"], ""]) | NAMES)
    data["actors"] = draw(st.permutations(list(actors.values())))
    if draw(st.booleans()):
        data = write_pattern(lay_out_pattern(read_pattern(data)))
        for node in data["processes"][0]["places"]:
            if draw(st.booleans()):
                del node["layout"]
    return data


@settings(max_examples=80, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(patterns() | decorated() | with_events() | cancelling())
def test_generated_patterns_import_back_unchanged(data: dict[str, Any]) -> None:
    pattern = read_pattern(data)
    assert_unchanged(pattern)
    assert_unchanged(lay_out_pattern(pattern))


@settings(max_examples=80, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(awkward())
def test_patterns_at_the_exporters_edges_import_back_unchanged(data: dict[str, Any]) -> None:
    assert_unchanged(read_pattern(data))


def _xpath(root: Any, path: str) -> list[Any]:
    found: list[Any] = root.xpath(path, namespaces={"bpmn": BPMN_NAMESPACE, "hrc": HRC_NAMESPACE})
    return found


def _with_a_task_added(text: str) -> str:
    """The export with a task `check` put into the flow `pa` (load -> inspect), in inspect's
    lane, as a person would draw it in bpmn-js: a new task and flow, without marks."""
    root = etree.fromstring(text.encode())
    flow = _one(root, "//bpmn:sequenceFlow[@id='pa']")
    target = flow.get("targetRef")
    flow.set("targetRef", "check")
    tag = f"{{{BPMN_NAMESPACE}}}"
    task = etree.Element(f"{tag}task", id="check", name="Check the part")
    flow.addprevious(task)
    flow.addnext(
        etree.Element(f"{tag}sequenceFlow", id="flow_new", sourceRef="check", targetRef=target)
    )
    lane = _one(root, f"//bpmn:lane[bpmn:flowNodeRef='{target}']")
    etree.SubElement(lane, f"{tag}flowNodeRef").text = "check"
    return str(etree.tostring(root, encoding="unicode"))


def test_a_task_added_in_another_tool_is_imported_through_the_mapping() -> None:
    pattern = read_pattern(configured())
    back = bpmn_to_pattern(_with_a_task_added(pattern_to_bpmn(pattern)))
    check = back.transition("check")
    assert check is not None
    assert (check.performer, check.label) == ("o1", "Check the part")
    operator = back.processes[0]
    assert {("pa", "check"), ("check", "flow_new")} <= set(operator.arcs)
    assert ("pa", "inspect") not in operator.arcs
    assert_configuration_comes_back(pattern, back)
    # The cobot's pool was not touched: it comes back exactly.
    assert write_pattern(back)["processes"][1] == write_pattern(pattern)["processes"][1]


def test_a_task_renamed_and_retyped_in_another_tool_comes_back_so_and_the_rest_unchanged() -> None:
    data = configured()
    root = etree.fromstring(pattern_to_bpmn(read_pattern(data)).encode())
    grasp = _one(root, "//bpmn:task[@id='grasp']")
    grasp.tag = f"{{{BPMN_NAMESPACE}}}userTask"
    grasp.set("name", "grasp the part")
    back = bpmn_to_pattern(etree.tostring(root, encoding="unicode"))
    task = next(t for t in data["processes"][1]["transitions"] if t["id"] == "grasp")
    task.update(label="grasp the part", bpmn="userTask")
    assert write_pattern(back) == write_pattern(read_pattern(data))


def test_an_element_whose_id_changed_is_no_longer_taken_for_what_it_stood_for() -> None:
    """A tool that copies an element keeps its attributes: the copy's mark names the original."""
    root = etree.fromstring(pattern_to_bpmn(read_pattern(configured())).encode())
    for reference in _xpath(root, "//*[@sourceRef='grasp' or @targetRef='grasp']"):
        for key in ("sourceRef", "targetRef"):
            if reference.get(key) == "grasp":
                reference.set(key, "grasp_copy")
    _one(root, "//bpmn:task[@id='grasp']").set("id", "grasp_copy")
    for reference in _xpath(root, "//*[text()='grasp']"):
        reference.text = "grasp_copy"
    back = bpmn_to_pattern(etree.tostring(root, encoding="unicode"))
    assert back.transition("grasp_copy") is not None
    cobot = back.processes[1]
    # Read through the mapping: every flow of the cobot's pool is a place of its own.
    assert len(cobot.places) > len(read_pattern(configured()).processes[1].places)


def test_a_pattern_without_layout_comes_back_without_one() -> None:
    data = configured()
    assert "layout" not in data
    back = write_pattern(assert_unchanged(read_pattern(data)))
    assert "layout" not in back
    assert all("layout" not in p for net in back["processes"] for p in net["places"])


def test_every_mark_names_an_element_of_its_process() -> None:
    root = etree.fromstring(pattern_to_bpmn(read_pattern(configured())).encode())
    for net in _xpath(root, "//bpmn:process"):
        ids = set(net.xpath(".//@id"))
        for element in net.xpath(".//*[@hrc:net]", namespaces={"hrc": HRC_NAMESPACE}):
            words = element.get(f"{{{HRC_NAMESPACE}}}net").split()
            assert words[0] in {"transition", "join", "place", "split", "merge", "arc"}
            assert words[1:] == [] if words[0] == "arc" else words[1] in ids
