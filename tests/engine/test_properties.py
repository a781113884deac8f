"""Properties over generated patterns: serialization round trip, soundness as a plain search
decides it (reset arcs included), and the runtime's firing rule as the textbook states it."""

import json
from collections import Counter
from typing import Any

from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from hrc.engine import check_pattern, read_pattern, write_pattern
from hrc.engine.document import dumps, loads
from hrc.engine.execution import build_execution_net
from hrc.engine.petri import Marking
from hrc.engine.rules import STRUCTURAL_CODES
from hrc.engine.runtime import CaseNet
from tests.engine.plain_search import plain_soundness
from tests.engine.strategies import cancelling, decorated, patterns

PROPERTY = settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])


@PROPERTY
@given(decorated())
def test_write_after_read_gives_the_document_back(data: dict[str, Any]) -> None:
    assert write_pattern(read_pattern(data)) == data
    assert loads(dumps(read_pattern(data))) == read_pattern(data)
    assert json.loads(dumps(read_pattern(data))) == data


@PROPERTY
@given(st.one_of(patterns(), cancelling()))
def test_the_soundness_verdict_equals_a_plain_exhaustive_search(data: dict[str, Any]) -> None:
    pattern = read_pattern(data)
    report = check_pattern(pattern)
    assert not any(e.code in STRUCTURAL_CODES for e in report.errors), report.as_dict()

    try:
        expected = plain_soundness(build_execution_net(pattern), limit=20_000)
    except RuntimeError:
        assume(False)  # too large for the yardstick; the engine is not compared on it

    assert report.sound is expected, report.as_dict()


@PROPERTY
@given(st.one_of(patterns(), cancelling()))
def test_every_witness_replays_from_the_initial_marking(data: dict[str, Any]) -> None:
    pattern = read_pattern(data)
    net = build_execution_net(pattern)
    by_label = {t.label: t for t in net.transitions}

    for issue in check_pattern(pattern).errors:
        marking = net.initial
        for label in issue.witness or ():
            transition = by_label[label]
            assert transition.is_enabled(marking), (label, issue.message)
            marking = transition.fire(marking)
        if issue.message.startswith("The pattern can get stuck"):
            assert net.enabled(marking) == []
            assert not net.is_final(marking)


def _emptied(data: dict[str, Any]) -> dict[str, set[str]]:
    """What each transition's `cancels` empties, read from the document as pattern-format.md says:
    the places, and for a task its running place and the func constraint places of its run."""
    process = data["processes"][0]
    performer = {t["id"]: t.get("performer") for t in process["transitions"]}
    kinds = {a["id"]: a["type"] for a in data["actors"]}
    run: dict[str, set[str]] = {t: {f"running:{t}"} for t, p in performer.items() if p}
    for c in data["constraints"]:
        if c["type"] == "func":
            a, b = c["from"], c["to"]
            s, d = (
                (b, a)
                if [kinds[performer[a]], kinds[performer[b]]] == ["operator", "cobot"]
                else (a, b)
            )
            run[s] |= {f"func-start:{s}>{d}", f"func-done:{d}>{s}"}
    return {
        t["id"]: {place for node in t.get("cancels", ()) for place in run.get(node, {node})}
        for t in process["transitions"]
    }


@PROPERTY
@given(cancelling(), st.data())
def test_the_runtime_fires_as_the_petri_net_firing_rule_with_resets_says(
    data: dict[str, Any], steps: st.DataObject
) -> None:
    # Every silent transition waits for a timer, so each firing is one call: ring, start, complete.
    for actor in data["actors"]:
        actor["program"] = "Coexistence_PickAndPlace"
    for transition in data["processes"][0]["transitions"]:
        if "performer" not in transition:
            transition["timer"] = "PT1S"
    net = CaseNet(read_pattern(data))
    emptied = _emptied(data)
    marking = net.initial
    for _ in range(30):
        assert net.settle(marking, {}) == (marking, [])
        enabled = [t for t in net.net.transitions if all(marking.get(p) >= n for p, n in t.pre)]
        if not enabled:
            break
        transition = steps.draw(st.sampled_from(enabled))
        tokens = Counter(dict(marking))
        tokens.subtract(dict(transition.pre))
        for place in emptied.get(transition.task, ()) if transition.kind == "silent" else ():
            tokens[place] = 0
        tokens.update(dict(transition.post))
        if transition.kind == "start":
            after = net.start(marking, transition.task)
        elif transition.kind == "complete":
            after = net.complete(marking, transition.task)
        else:
            assert (transition.id, 1000) in net.waiting_timers(marking)
            after = net.ring(marking, transition.id)
        assert after == Marking(tokens)
        marking = after
