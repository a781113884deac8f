"""Properties over generated patterns: serialization round trip, and soundness as a plain search decides it."""

import json
from typing import Any

from hypothesis import HealthCheck, assume, given, settings

from hrc.engine import check_pattern, read_pattern, write_pattern
from hrc.engine.document import dumps, loads
from hrc.engine.execution import build_execution_net
from hrc.engine.rules import STRUCTURAL_CODES
from tests.engine.plain_search import plain_soundness
from tests.engine.strategies import decorated, patterns

PROPERTY = settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])


@PROPERTY
@given(decorated())
def test_write_after_read_gives_the_document_back(data: dict[str, Any]) -> None:
    assert write_pattern(read_pattern(data)) == data
    assert loads(dumps(read_pattern(data))) == read_pattern(data)
    assert json.loads(dumps(read_pattern(data))) == data


@PROPERTY
@given(patterns())
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
@given(patterns())
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
