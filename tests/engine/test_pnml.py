"""PNML export and import: our own files round-trip exactly; other tools' nets import without actors."""

import json
import re
import xml.etree.ElementTree as ET
from dataclasses import replace
from pathlib import Path
from typing import Any

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from hrc.engine.check import check_pattern
from hrc.engine.document import FormatError, read_pattern, write_pattern
from hrc.engine.model import (
    ACTOR_TYPES,
    CONSTRAINT_TYPES,
    PATTERN_NAMES,
    Actor,
    Constraint,
    Pattern,
    Place,
    Process,
    Transition,
)
from hrc.engine.pnml import PNML_NAMESPACE, PTNET_TYPE, pattern_to_pnml, pnml_to_pattern
from tests.hostile_xml import BILLION_LAUGHS, EXTERNAL_ENTITY

EXAMPLES = Path(__file__).resolve().parents[2] / "hrc" / "patterns" / "examples"
NS = {"pnml": PNML_NAMESPACE}


def round_trip(pattern: Pattern) -> Pattern:
    return pnml_to_pattern(pattern_to_pnml(pattern))


def assert_round_trips(pattern: Pattern) -> None:
    back = round_trip(pattern)
    assert back == pattern
    # `extra` is compare=False in the model: the written documents show it.
    assert write_pattern(back) == write_pattern(pattern)


def format_error(text: str | bytes) -> FormatError:
    with pytest.raises(FormatError) as caught:
        pnml_to_pattern(text)
    assert caught.value.issues
    assert all(issue.code == "format" for issue in caught.value.issues)
    return caught.value


# Our own files ---------------------------------------------------------------------------


@pytest.mark.parametrize("path", sorted(EXAMPLES.glob("*.json")), ids=lambda path: path.stem)
def test_example_library_round_trips(path: Path) -> None:
    assert_round_trips(read_pattern(json.loads(path.read_text())))


def test_the_thesis_examples_are_among_the_round_tripped() -> None:
    names = {path.stem for path in EXAMPLES.glob("*.json")}
    assert {
        "synch_1o1c_assembly",
        "coll_1o1c_collaborative_assembly",
        "coex_1o1c_pick_and_place",
    } <= names


def layout_document() -> dict[str, Any]:
    return {
        "format": "hrc-pattern/1",
        "name": 'Layout & <config> "kept"',
        "declared_pattern": "synchronized",
        "editor": {"zoom": 1.5, "grid": [10, 10]},
        "actors": [
            {"id": "c", "type": "cobot", "driver": {"kind": "ur", "ip": "10.0.0.2"}},
            {"id": "o", "type": "operator", "colour": "#f80"},
        ],
        "processes": [
            {
                "id": "N",
                "workpiece": "w",
                "actors": ["c", "o"],
                "lane_order": ["o", "c"],
                "places": [
                    {"id": "p1", "tokens": 1, "x": 10, "y": 20.5},
                    {"id": "p2", "name": "buffer", "capacity": None},
                    {"id": "p3", "tokens": 0},
                ],
                "transitions": [
                    {"id": "t1", "x": 40, "y": 20},
                    {"id": "tc1", "performer": "c", "label": "pick", "program": {"speed": 0.25}},
                    {"id": "to1", "performer": "o", "label": "", "instructions": ["a", "b"]},
                ],
                "arcs": [["p1", "t1"], ["t1", "p2"], ["p2", "tc1"], ["tc1", "p3"], ["p3", "to1"]],
            }
        ],
        "constraints": [{"from": "tc1", "to": "to1", "type": "time", "note": "ü ✓ 🤖"}],
    }


def test_unknown_keys_survive_at_every_level() -> None:
    document = layout_document()
    pattern = read_pattern(document)
    assert_round_trips(pattern)
    assert write_pattern(round_trip(pattern)) == document


def test_editor_positions_are_also_written_as_standard_graphics() -> None:
    root = ET.fromstring(pattern_to_pnml(read_pattern(layout_document())))
    position = root.find(".//pnml:place[@id='p1']/pnml:graphics/pnml:position", NS)
    assert position is not None
    assert (float(position.get("x", "")), float(position.get("y", ""))) == (10, 20.5)
    assert root.find(".//pnml:place[@id='p2']/pnml:graphics", NS) is None


def test_the_toolspecific_wins_over_graphics_on_reimport() -> None:
    text = pattern_to_pnml(read_pattern(layout_document()))
    moved = text.replace('x="10"', 'x="999"')
    assert moved != text
    place = round_trip_text(moved).processes[0].places[0]
    assert place.extra == {"x": 10, "y": 20.5}


def round_trip_text(text: str) -> Pattern:
    return pnml_to_pattern(text)


def tricky_pattern() -> Pattern:
    """Ids and texts XML cannot hold as written, duplicates, and arcs that collide with generated ids."""
    return Pattern(
        name="line\r\nbreak \x00 and \ud800",
        actors=(Actor("c", "cobot"), Actor("o 1", "operator")),
        processes=(
            Process(
                id="1st net",
                workpiece="",
                actors=("c", "o 1"),
                places=(
                    Place("1"),
                    Place("p1", 2),
                    Place("p1", 0),
                    Place("x:y", None, {"": "empty key"}),
                ),
                transitions=(
                    Transition("t1", "c", "tab\tand\rcarriage"),
                    Transition("t 2", "o 1", "\ufffe"),
                    Transition("page1"),
                ),
                arcs=(
                    ("1", "t1"),
                    ("t1", "p1"),
                    ("p2", "a1"),
                    ("1st net", "t 2"),
                    ("ghost", "x:y"),
                    # Not a node here, but the id the writer generates for place "1".
                    ("p3", "t 2"),
                ),
            ),
            Process(
                "N2",
                None,
                (),
                (Place("p2", extra={"label": "an arc of 1st net ends here"}),),
                (),
                (),
            ),
        ),
        constraints=(Constraint("t1", "t 2", "space"), Constraint("t1", "t1", "colour")),
        declared_pattern=None,
        extra={"\x01": ["\ud83e", "\r"]},
    )


def test_ids_and_texts_xml_cannot_hold_still_round_trip() -> None:
    assert_round_trips(tricky_pattern())


def test_written_ids_are_unique_xml_ids() -> None:
    root = ET.fromstring(pattern_to_pnml(tricky_pattern()))
    ids = [element.get("id") for element in root.iter() if element.get("id") is not None]
    assert len(ids) == len(set(ids))
    assert all(re.fullmatch(r"[A-Za-z_][\w.\-]*", element_id or "") for element_id in ids)


def test_output_is_standard_pnml_with_one_page_per_process() -> None:
    pattern = read_pattern(json.loads((EXAMPLES / "coex_1o1c_pick_and_place.json").read_text()))
    root = ET.fromstring(pattern_to_pnml(pattern))
    assert root.tag == f"{{{PNML_NAMESPACE}}}pnml"
    nets = root.findall("pnml:net", NS)
    assert [net.get("type") for net in nets] == [PTNET_TYPE]
    assert [page.get("id") for page in nets[0].findall("pnml:page", NS)] == ["N1", "N2"]
    assert root.findtext("pnml:net/pnml:name/pnml:text", namespaces=NS) == pattern.name
    assert (
        root.findtext(".//pnml:place[@id='p11']/pnml:initialMarking/pnml:text", namespaces=NS)
        == "1"
    )
    assert root.find(".//pnml:place[@id='p12']/pnml:initialMarking", NS) is None
    label = root.findtext(".//pnml:transition[@id='t11']/pnml:name/pnml:text", namespaces=NS)
    assert label == "pick part"
    arc_ids = [arc.get("id") for arc in root.iter(f"{{{PNML_NAMESPACE}}}arc")]
    assert len(arc_ids) == 10
    assert len(set(arc_ids)) == 10


def strip_hrc_data(text: str) -> str:
    root = ET.fromstring(text)
    for parent in root.iter():
        for block in parent.findall("pnml:toolspecific[@tool='hrc']", NS):
            parent.remove(block)
    return ET.tostring(root, encoding="unicode")


def test_our_file_without_its_hrc_data_reads_as_the_plain_net() -> None:
    pattern = read_pattern(json.loads((EXAMPLES / "synch_1o1c_assembly.json").read_text()))
    plain = pnml_to_pattern(strip_hrc_data(pattern_to_pnml(pattern)))
    assert plain.actors == ()
    assert plain.constraints == ()
    assert plain.name == pattern.name
    (process,) = plain.processes
    (original,) = pattern.processes
    assert process.places == original.places
    assert process.arcs == original.arcs
    # Labels survive; silent steps stay unlabelled; performers are hrc data.
    assert [(t.id, t.label) for t in process.transitions] == [
        (t.id, t.label) for t in original.transitions
    ]
    assert all(t.performer is None for t in process.transitions)


# Property: any pattern round-trips -------------------------------------------------------

# All of unicode, surrogates and control characters included (XML cannot hold them), and
# ids that collide with the ones the writer generates. One `characters` alphabet keeps
# hypothesis on its fast path for text.
_alphabet = st.characters(exclude_categories=())
_text = st.text(_alphabet, max_size=6)
_ids = st.one_of(
    st.sampled_from(["p1", "t1", "a1", "a2", "net1", "page1", "1", "x y", "N"]),
    st.text(_alphabet, min_size=1, max_size=5),
)
_json = st.recursive(
    st.none() | st.booleans() | st.integers() | st.floats(allow_nan=False) | _text,
    lambda inner: st.lists(inner, max_size=3) | st.dictionaries(_text, inner, max_size=3),
    max_leaves=4,
)
_coordinate = st.integers(-1000, 1000) | st.floats(allow_nan=False) | st.booleans()

PATTERN_KEYS = {"format", "name", "declared_pattern", "actors", "processes", "constraints"}
ACTOR_KEYS = {"id", "type"}
PROCESS_KEYS = {"id", "workpiece", "actors", "places", "transitions", "arcs"}
PLACE_KEYS = {"id", "tokens"}
TRANSITION_KEYS = {"id", "performer", "label"}
CONSTRAINT_KEYS = {"from", "to", "type"}


def _extras(known: set[str]) -> st.SearchStrategy[dict[str, Any]]:
    unknown = st.dictionaries(_text.filter(lambda key: key not in known), _json, max_size=2)
    layout_keys = [key for key in ("x", "y", "name") if key not in known]
    position = st.dictionaries(st.sampled_from(layout_keys), _coordinate | _text, max_size=3)
    # Mostly empty, as in real documents; generating rich extras everywhere is slow.
    return st.just({}) | st.builds(lambda a, b: {**a, **b}, unknown, position)


# Built once: strategies made inside a draw are validated again on every example, which
# made generation, not the round trip, take seconds.
_coin = st.booleans()
_index = st.integers(min_value=0, max_value=2**16)
_few = st.integers(min_value=0, max_value=3)
_places = st.lists(
    st.builds(Place, _ids, st.none() | st.integers(0, 10**30), _extras(PLACE_KEYS)), max_size=3
)
_transitions = st.lists(
    st.builds(Transition, _ids, st.none() | _ids, st.none() | _text, _extras(TRANSITION_KEYS)),
    max_size=3,
)
_actors = st.lists(
    st.builds(Actor, _ids, st.sampled_from(ACTOR_TYPES), _extras(ACTOR_KEYS)), max_size=3
)
_constraint_types = st.sampled_from(CONSTRAINT_TYPES) | st.text(_alphabet, min_size=1, max_size=4)
_optional_text = st.none() | _text
_process_extras = _extras(PROCESS_KEYS)
_constraint_extras = _extras(CONSTRAINT_KEYS)
_pattern_extras = _extras(PATTERN_KEYS)
_declared = st.none() | st.sampled_from(PATTERN_NAMES)


def _pick(draw: st.DrawFn, choices: list[str]) -> str:
    """Mostly one of `choices` (an id that exists), sometimes any id."""
    existing: bool = draw(_coin)
    if choices and existing:
        return choices[draw(_index) % len(choices)]
    return draw(_ids)


def _process(draw: st.DrawFn, actor_ids: list[str]) -> Process:
    places: list[Place] = draw(_places)
    transitions = [
        replace(t, performer=_pick(draw, actor_ids)) if draw(_coin) else t
        for t in draw(_transitions)
    ]
    nodes = [p.id for p in places] + [t.id for t in transitions]
    return Process(
        id=draw(_ids),
        workpiece=draw(_optional_text),
        actors=tuple(_pick(draw, actor_ids) for _ in range(draw(_few))),
        places=tuple(places),
        transitions=tuple(transitions),
        arcs=tuple((_pick(draw, nodes), _pick(draw, nodes)) for _ in range(draw(_few) * 2)),
        extra=draw(_process_extras),
    )


@st.composite
def patterns(draw: st.DrawFn) -> Pattern:
    actors: list[Actor] = draw(_actors)
    processes = [_process(draw, [a.id for a in actors]) for _ in range(1 + draw(_few))]
    tasks = [t.id for p in processes for t in p.transitions]
    constraints = [
        Constraint(
            _pick(draw, tasks),
            _pick(draw, tasks),
            draw(_constraint_types),
            draw(_constraint_extras),
        )
        for _ in range(draw(_few))
    ]
    return Pattern(
        name=draw(_text),
        actors=tuple(actors),
        processes=tuple(processes),
        constraints=tuple(constraints),
        declared_pattern=draw(_declared),
        extra=draw(_pattern_extras),
    )


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(patterns())
def test_any_pattern_round_trips_through_pnml(pattern: Pattern) -> None:
    assert read_pattern(write_pattern(pattern)) == pattern  # the generator makes valid documents
    assert_round_trips(pattern)


# Nets from other tools -------------------------------------------------------------------

# As pm4py writes it: no xmlns, the core model type, one page, numeric arc ids, an
# invisible transition, graphics, and ProM's final marking.
PM4PY_NET = """<?xml version='1.0' encoding='UTF-8'?>
<pnml>
  <net id="imported_1700000000" type="http://www.pnml.org/version-2009/grammar/pnmlcoremodel">
    <name><text>Assembly line</text></name>
    <page id="n0">
      <place id="source">
        <name><text>source</text></name>
        <initialMarking><text>1</text></initialMarking>
      </place>
      <place id="p_3"><name><text>buffer</text></name></place>
      <place id="sink"><name><text>sink</text></name></place>
      <transition id="t_pick">
        <name><text>pick insert</text></name>
        <graphics><position x="120.0" y="40.5"/><dimension x="40.0" y="40.0"/></graphics>
      </transition>
      <transition id="skip_1">
        <name><text>skip_1</text></name>
        <toolspecific tool="ProM" version="6.4" activity="$invisible$" localNodeID="5b1c"/>
      </transition>
      <arc id="140512" source="source" target="t_pick"/>
      <arc id="140513" source="t_pick" target="p_3"><inscription><text>1</text></inscription></arc>
      <arc id="140514" source="p_3" target="skip_1"/>
      <arc id="140515" source="skip_1" target="sink"/>
    </page>
    <finalmarkings>
      <marking><place idref="sink"><text>1</text></place></marking>
    </finalmarkings>
  </net>
</pnml>
"""


def test_a_pm4py_net_imports_as_a_net_without_actors_working_on_the_nets_workpiece() -> None:
    pattern = pnml_to_pattern(PM4PY_NET.encode())
    assert pattern == Pattern(
        name="Assembly line",
        actors=(),
        processes=(
            Process(
                id="imported_1700000000",
                workpiece="Assembly line",  # named after the net
                actors=(),
                places=(Place("source", 1), Place("p_3"), Place("sink")),
                transitions=(Transition("t_pick", None, "pick insert"), Transition("skip_1")),
                arcs=(
                    ("source", "t_pick"),
                    ("t_pick", "p_3"),
                    ("p_3", "skip_1"),
                    ("skip_1", "sink"),
                ),
            ),
        ),
        constraints=(),
    )
    process = pattern.processes[0]
    assert process.places[1].extra == {"name": "buffer"}
    assert process.transitions[0].extra == {"x": 120, "y": 40.5}


def test_a_foreign_net_checks_as_a_draft_that_needs_lanes_but_has_its_workpiece() -> None:
    report = check_pattern(pnml_to_pattern(PM4PY_NET.encode()))

    assert [(i.code, i.elements) for i in report.errors] == [
        ("no-actors", ("imported_1700000000",))
    ]


def test_pages_are_flattened_and_references_resolved() -> None:
    text = f"""<pnml xmlns="{PNML_NAMESPACE}">
      <net id="net" type="{PTNET_TYPE}">
        <page id="top">
          <place id="p1"><initialMarking><text> 2 </text></initialMarking></place>
          <transition id="t1"/>
          <arc id="a1" source="p1" target="t1"/>
          <page id="sub">
            <referenceTransition id="rt" ref="t1"/>
            <referencePlace id="rp" ref="p1"/>
            <referencePlace id="rrp" ref="rp"/>
            <place id="p2"/>
            <arc id="a2" source="rt" target="p2"/>
            <arc id="a3" source="rt" target="rrp"/>
          </page>
        </page>
      </net>
    </pnml>"""
    pattern = pnml_to_pattern(text)
    assert pattern.name == "net"
    (process,) = pattern.processes
    assert process.places == (Place("p1", 2), Place("p2"))
    assert process.transitions == (Transition("t1"),)
    assert process.arcs == (("p1", "t1"), ("t1", "p2"), ("t1", "p1"))


def test_each_foreign_net_becomes_a_process_and_dangling_arcs_are_kept() -> None:
    text = """<pnml>
      <net id="left"><page id="a"><place id="p1"/><arc id="x1" source="p1" target="ghost"/></page></net>
      <net id="right"><name><text>ignored: the first net names the pattern</text></name>
        <place id="q1"/><transition id="u1"/><arc id="x2" source="u1" target="q1"/></net>
    </pnml>"""
    pattern = pnml_to_pattern(text)
    assert pattern.name == "left"
    assert [p.id for p in pattern.processes] == ["left", "right"]
    assert pattern.processes[0].arcs == (("p1", "ghost"),)
    assert pattern.processes[1].arcs == (("u1", "q1"),)


# PIPE's dialect ------------------------------------------------------------------------------


def pipe_net(
    places: str, transitions: str, arcs: str, tokens: str = '<token id="Default" enabled="true"/>'
) -> str:
    """A net as PIPE writes it: no namespace, type `P/T net`, names and numbers in `<value>`."""
    return f"""<?xml version="1.0" encoding="iso-8859-1"?>
<pnml><net id="Net-One" type="P/T net">{tokens}
<labels x="10" y="10" width="40" height="20" border="false"><text>a note</text></labels>
{places}{transitions}{arcs}<stategroup name="done" id="s1"/></net></pnml>"""


def pipe_place(place_id: str, name: str, marking: str, capacity: str = "0") -> str:
    return f"""<place id="{place_id}"><graphics><position x="135.0" y="120.0"/></graphics>
<name><value>{name}</value><graphics/></name>
<initialMarking><value>{marking}</value><graphics/></initialMarking>
<capacity><value>{capacity}</value></capacity></place>"""


def pipe_transition(transition_id: str, name: str, timed: str = "true") -> str:
    return f"""<transition id="{transition_id}"><graphics><position x="255.0" y="120.0"/></graphics>
<name><value>{name}</value><graphics/></name><orientation><value>0</value></orientation>
<rate><value>2.5</value></rate><timed><value>{timed}</value></timed>
<infiniteServer><value>false</value></infiniteServer><priority><value>1</value></priority>
</transition>"""


def pipe_arc(source: str, target: str, weight: str = "Default,1", kind: str = "normal") -> str:
    return f"""<arc id="{source} to {target}" source="{source}" target="{target}">
<arcpath id="000" x="150" y="120" curvePoint="false"/><type value="{kind}"/>
<inscription><value>{weight}</value><graphics/></inscription><tagged><value>false</value></tagged></arc>"""


PIPE_PLACES = (
    pipe_place("P0", "waiting room", "Default,1")
    + pipe_place("P1", "in treatment", "")
    + pipe_place("P2", "P2", "0")
)
PIPE_TRANSITIONS = pipe_transition("T0", "admit") + pipe_transition("T1", "T1", timed="false")
PIPE_ARCS = (
    pipe_arc("P0", "T0") + pipe_arc("T0", "P1", "1") + pipe_arc("P1", "T1") + pipe_arc("T1", "P2")
)


def test_a_pipe_net_reads_as_its_p_t_net_with_names_and_markings_and_without_timing() -> None:
    pattern = pnml_to_pattern(pipe_net(PIPE_PLACES, PIPE_TRANSITIONS, PIPE_ARCS))

    (process,) = pattern.processes
    assert process.id == "Net-One"
    assert process.places == (Place("P0", 1), Place("P1", 0), Place("P2", 0))
    assert process.places[0].extra == {"name": "waiting room", "x": 135, "y": 120}
    assert process.transitions == (Transition("T0", None, "admit"), Transition("T1", None, "T1"))
    assert process.arcs == (("P0", "T0"), ("T0", "P1"), ("P1", "T1"), ("T1", "P2"))
    assert "rate" not in json.dumps(write_pattern(pattern))


def test_a_pipe_net_checks_like_any_foreign_net() -> None:
    report = check_pattern(pnml_to_pattern(pipe_net(PIPE_PLACES, PIPE_TRANSITIONS, PIPE_ARCS)))

    assert [issue.code for issue in report.errors] == ["no-actors"]


def test_pipe_colours_declared_but_one_used_read_as_a_p_t_net() -> None:
    tokens = '<token id="Default" enabled="true"/><token id="Red" enabled="true"/>'
    places = PIPE_PLACES.replace("Default,1", "Default,2,Red,0")

    pattern = pnml_to_pattern(pipe_net(places, PIPE_TRANSITIONS, PIPE_ARCS, tokens))

    assert pattern.processes[0].places[0].tokens == 2


def test_a_coloured_pipe_net_is_refused_naming_the_net_and_its_colours() -> None:
    tokens = '<token id="Default" enabled="true"/><token id="Red" enabled="true"/>'
    arcs = PIPE_ARCS.replace(pipe_arc("P1", "T1"), pipe_arc("P1", "T1", "Default,0,Red,1"))

    (issue,) = format_error(pipe_net(PIPE_PLACES, PIPE_TRANSITIONS, arcs, tokens)).issues

    assert issue.elements == ("Net-One",)
    assert issue.message.startswith("Net Net-One is a coloured PIPE net")
    assert "2 colours, Default (3 elements), Red (1 element)" in issue.message


def test_a_pipe_inhibitor_arc_is_refused_naming_the_arc_and_its_ends_by_name() -> None:
    arcs = PIPE_ARCS.replace(pipe_arc("P0", "T0"), pipe_arc("P0", "T0", kind="inhibitor"))

    (issue,) = format_error(pipe_net(PIPE_PLACES, PIPE_TRANSITIONS, arcs)).issues

    assert issue.elements == ("P0 to T0",)
    assert issue.message.startswith(
        "Arc P0 to T0 (“waiting room” -> “admit”) is a PIPE inhibitor arc"
    )


def test_a_pipe_place_with_a_capacity_is_refused_by_name() -> None:
    places = PIPE_PLACES.replace(
        pipe_place("P1", "in treatment", ""), pipe_place("P1", "in treatment", "", capacity="4")
    )

    (issue,) = format_error(pipe_net(places, PIPE_TRANSITIONS, PIPE_ARCS)).issues

    assert issue.elements == ("P1",)
    assert issue.message.startswith("Place “in treatment” (P1) has a capacity of '4'")


def test_a_pipe_weight_is_read_per_colour_and_refused_by_the_arcs_names() -> None:
    arcs = PIPE_ARCS.replace(pipe_arc("P0", "T0"), pipe_arc("P0", "T0", "Default,3"))

    (issue,) = format_error(pipe_net(PIPE_PLACES, PIPE_TRANSITIONS, arcs)).issues

    assert issue.message.startswith("Arc P0 to T0 (“waiting room” -> “admit”) has weight 3")


def test_a_pipe_marking_that_is_no_number_is_refused_by_the_places_name() -> None:
    places = PIPE_PLACES.replace("Default,1", "Default,lots")

    (issue,) = format_error(pipe_net(places, PIPE_TRANSITIONS, PIPE_ARCS)).issues

    assert issue.message == (
        "The initial marking of place “waiting room” (P0) must be a whole number ≥ 0, "
        "got 'Default,lots'."
    )


def test_a_foreign_net_without_an_id_is_named_net() -> None:
    text = pipe_net(PIPE_PLACES, PIPE_TRANSITIONS, PIPE_ARCS).replace(
        '<net id="Net-One" type="P/T net">', "<net>"
    )

    assert [process.id for process in pnml_to_pattern(text).processes] == ["net"]


# Bad input -------------------------------------------------------------------------------


def net(body: str, net_type: str = PTNET_TYPE) -> str:
    return f'<pnml xmlns="{PNML_NAMESPACE}"><net id="n" type="{net_type}"><page id="g">{body}</page></net></pnml>'


def own_file(changes: list[tuple[str, str]]) -> str:
    """Our export of `layout_document`, with some of its text replaced."""
    text = pattern_to_pnml(read_pattern(layout_document()))
    for old, new in changes:
        assert text.count(old) == 1
        text = text.replace(old, new)
    return text


@pytest.mark.parametrize(
    ("text", "fragments", "elements"),
    [
        pytest.param("this is not XML", ["not XML"], [], id="not-xml"),
        pytest.param(b"<pnml><net id='n'>\xff</net></pnml>", ["not XML"], [], id="not-utf8"),
        pytest.param("<pnml><net id='n'></pnml>", ["not XML", "line 1"], [], id="unclosed"),
        pytest.param(
            b"<?xml version='1.0' encoding='klingon'?><pnml/>",
            ["unknown encoding", "klingon"],
            [],
            id="unknown-encoding",
        ),
        pytest.param(BILLION_LAUGHS, ["DTD", "XML bomb"], [], id="billion-laughs"),
        pytest.param(EXTERNAL_ENTITY, ["DTD", "external entit"], [], id="external-entity"),
        pytest.param("<!DOCTYPE pnml><pnml/>", ["DTD"], [], id="doctype"),
        pytest.param(
            "<bpmn:definitions xmlns:bpmn='x'/>",
            ["<definitions>", "not a PNML"],
            [],
            id="wrong-root",
        ),
        pytest.param(
            "<pnml xmlns='http://example.org/pnml'/>", ["namespace"], [], id="wrong-namespace"
        ),
        pytest.param(f"<pnml xmlns='{PNML_NAMESPACE}'/>", ["no <net>"], [], id="no-net"),
        pytest.param(
            "<pnml><net><toolspecific tool='hrc' version='1'>{}</toolspecific></net></pnml>",
            ["<net> has no id"],
            [],
            id="own-net-without-id",
        ),
        pytest.param(
            "<pnml><net type='x'/></pnml>", ["Net net has type 'x'"], ["net"], id="net-type"
        ),
        pytest.param(
            net("", "http://www.pnml.org/version-2009/grammar/symmetricnet"),
            ["symmetricnet", "P/T"],
            ["n"],
            id="not-pt-net",
        ),
        pytest.param(net("<place/>"), ["<place> has no id"], [], id="place-without-id"),
        pytest.param(
            net("<transition><name><text>x</text></name></transition>"),
            ["<transition> has no id"],
            [],
            id="transition-without-id",
        ),
        pytest.param(
            net("<place id='p'/><transition id='t'/><arc source='p' target='t'/>"),
            ["<arc> from p to t has no id"],
            [],
            id="arc-without-id",
        ),
        pytest.param(
            net("<place id='p'/><arc id='a' source='p'/>"),
            ["Arc a", "source and a target"],
            ["a"],
            id="arc-without-target",
        ),
        pytest.param(
            net(
                "<place id='p'/><transition id='t'/><arc id='a7' source='p' target='t'><inscription><text>2</text></inscription></arc>"
            ),
            ["a7", "weight 2", "no weighted arcs"],
            ["a7"],
            id="weighted-arc",
        ),
        pytest.param(
            net(
                "<place id='p'/><transition id='t'/><arc id='a7' source='p' target='t'><inscription><text>x</text></inscription></arc>"
            ),
            ["arc a7", "'x'"],
            ["a7"],
            id="non-numeric-inscription",
        ),
        pytest.param(
            net("<place id='p9'><initialMarking><text>two</text></initialMarking></place>"),
            ["place p9", "'two'", "whole number"],
            ["p9"],
            id="non-numeric-marking",
        ),
        pytest.param(
            net("<place id='p9'><initialMarking><text>-1</text></initialMarking></place>"),
            ["place p9", "'-1'"],
            ["p9"],
            id="negative-marking",
        ),
        pytest.param(
            net("<place id='p9'><initialMarking><text>1.5</text></initialMarking></place>"),
            ["place p9", "'1.5'"],
            ["p9"],
            id="fractional-marking",
        ),
        pytest.param(
            net("<place id='p9'><initialMarking/></place>"),
            ["place p9", "nothing"],
            ["p9"],
            id="empty-marking",
        ),
        pytest.param(
            net("<referencePlace id='r' ref='nowhere'/>"),
            ["r", "nowhere", "does not exist"],
            ["r"],
            id="dangling-reference",
        ),
        pytest.param(
            net("<referencePlace id='r1' ref='r2'/><referencePlace id='r2' ref='r1'/>"),
            ["References r1, r2 refer to each other in a cycle"],
            ["r1", "r2"],
            id="reference-cycle",
        ),
        pytest.param(
            net("<transition id='t'/><referencePlace id='r' ref='t'/>"),
            ["must refer to a place", "t is a transition"],
            ["r", "t"],
            id="reference-kind",
        ),
        pytest.param(
            "<pnml><net id='a'><toolspecific tool='hrc' version='1'>{}</toolspecific></net><net id='b'/></pnml>",
            ["2 nets"],
            [],
            id="own-file-with-two-nets",
        ),
    ],
)
def test_bad_input_is_a_format_error_naming_the_problem(
    text: str | bytes, fragments: list[str], elements: list[str]
) -> None:
    raised = format_error(text)
    for fragment in fragments:
        assert fragment in str(raised)
    assert {element for issue in raised.issues for element in issue.elements} >= set(elements)


def test_an_external_entity_is_never_read() -> None:
    assert "root:" not in str(format_error(EXTERNAL_ENTITY))


@pytest.mark.parametrize(
    ("changes", "fragments", "elements"),
    [
        pytest.param(
            [('{"performer": "c", "program"', '{"performer": 7, "program"')],
            ["performer must be a string", "number 7"],
            ["tc1"],
            id="wrong-shape",
        ),
        pytest.param(
            [('"type": "cobot"', '"type": "robot"')],
            ['"cobot" or "operator"', '"robot"'],
            ["c"],
            id="unknown-actor-type",
        ),
        pytest.param(
            [('{"performer": "c", "program"', '{"performer": "c" "program"')],
            ["transition tc1", "not JSON"],
            ["tc1"],
            id="not-json",
        ),
        pytest.param(
            [('{"workpiece": "w", "actors": ["c", "o"], "lane_order": ["o", "c"]}', '["w"]')],
            ["page N", "JSON object"],
            ["N"],
            id="not-an-object",
        ),
        pytest.param(
            [('version="1">{"workpiece"', 'version="2">{"workpiece"')],
            ["page N", "version '2'"],
            ["N"],
            id="unknown-version",
        ),
        pytest.param(
            [('<page id="N">', "<page>")], ["A <page> has no id"], [], id="page-without-id"
        ),
        pytest.param(
            [("</page>", '</page><place id="stray"/>')],
            ["outside any <page>"],
            ["net1"],
            id="place-outside-page",
        ),
        pytest.param(
            [('"format": "hrc-pattern/1"', '"format": "hrc-pattern/9"')],
            ["hrc-pattern/1", "hrc-pattern/9"],
            [],
            id="unknown-format",
        ),
        pytest.param(
            [
                (
                    '{"x": 40, "y": 20}</toolspecific>',
                    '{"x": 40, "y": 20}</toolspecific><toolspecific tool="hrc" version="1">{}</toolspecific>',
                )
            ],
            ["transition t1", "2 hrc toolspecific blocks"],
            ["t1"],
            id="two-blocks",
        ),
        pytest.param(
            [('{"performer": "c", "program": {"speed": 0.25}}', "[" * 100_000 + "]" * 100_000)],
            ["transition tc1", "JSON"],
            ["tc1"],
            id="deeply-nested",
        ),
    ],
)
def test_broken_hrc_data_is_a_format_error(
    changes: list[tuple[str, str]], fragments: list[str], elements: list[str]
) -> None:
    raised = format_error(own_file(changes))
    for fragment in fragments:
        assert fragment in str(raised)
    assert {element for issue in raised.issues for element in issue.elements} >= set(elements)


def test_a_reference_cycle_is_reported_once() -> None:
    text = net(
        "<referencePlace id='r0' ref='r1'/>"
        "<referencePlace id='r1' ref='r2'/><referencePlace id='r2' ref='r1'/>"
    )
    assert [issue.elements for issue in format_error(text).issues] == [("r1", "r2")]


def test_every_problem_in_a_file_is_reported_at_once() -> None:
    text = net(
        "<place id='p1'><initialMarking><text>x</text></initialMarking></place>"
        "<place id='p2'><initialMarking><text>y</text></initialMarking></place>"
    )
    assert [issue.elements for issue in format_error(text).issues] == [("p1",), ("p2",)]
