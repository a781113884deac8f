"""Space constraints at run time, the engine's side: which pairs a pattern has, and who waits
or is interrupted when one task of a pair starts while the other runs (`entering_area`)."""

import pytest

from hrc.engine import read_pattern
from hrc.engine.runtime import AreaRule, CaseNet, SpacePair, entering_area
from hrc.engine.taskconfig import config_issues
from tests.engine.builders import document, process


def _two_of(kind: str, other: str, mode: str | None = None) -> CaseNet:
    """Two lanes side by side, `a1` of actor a (`kind`) and `b1` of actor b (`other`), under one
    space constraint."""
    lanes = process(
        "N", "p1 t1 p2 a1 p3 t2 p9", "t1 p4 b1 p5 t2", performers={"a1": "a", "b1": "b"}
    )
    data = document(lanes, constraints=[("a1", "b1", "space")], actors={"a": kind, "b": other})
    for actor in data["actors"]:
        actor.setdefault("program", "Coexistence_PickAndPlace") if actor[
            "type"
        ] == "cobot" else None
    if mode is not None:
        data["constraints"][0]["interrupt"] = mode
    return CaseNet(read_pattern(data))


@pytest.mark.parametrize(
    ("kinds", "mode", "expected"),
    [
        (("operator", "operator"), None, "wait"),
        (("cobot", "cobot"), None, "wait"),
        (("cobot", "cobot"), "pause", "pause"),
        (("operator", "cobot"), None, "pause"),
        (("cobot", "operator"), "slow", "slow"),
    ],
)
def test_every_pair_of_actor_types_gives_a_pair_with_its_mode(
    kinds: tuple[str, str], mode: str | None, expected: str
) -> None:
    net = _two_of(*kinds, mode=mode)

    assert net.space_pairs == (SpacePair("a1", "b1", kinds, expected),)
    assert net.space_tasks == {"a1", "b1"}


def test_a_mode_the_pair_does_not_have_is_a_config_issue() -> None:
    lanes = process(
        "N", "p1 t1 p2 a1 p3 t2 p9", "t1 p4 b1 p5 t2", performers={"a1": "a", "b1": "b"}
    )
    data = document(
        lanes, constraints=[("a1", "b1", "space")], actors={"a": "operator", "b": "operator"}
    )
    data["constraints"][0]["interrupt"] = "slow"

    [issue] = config_issues(read_pattern(data))

    assert "interrupt 'slow'; it must be one of wait" in issue.message


OPERATORS = SpacePair("o1", "o2", ("operator", "operator"), "wait")
COBOTS_WAIT = SpacePair("c1", "c2", ("cobot", "cobot"), "wait")
COBOTS_PAUSE = SpacePair("c1", "c2", ("cobot", "cobot"), "pause")
PAUSE = SpacePair("o1", "c1", ("operator", "cobot"), "pause")
SLOW = SpacePair("c1", "o1", ("cobot", "operator"), "slow")


@pytest.mark.parametrize(
    ("pair", "entering", "rule"),
    [
        # A person is never paused by software: the later operator is refused.
        (OPERATORS, "o2", AreaRule("o2", "o1", "refused")),
        (OPERATORS, "o1", AreaRule("o1", "o2", "refused")),
        # Two cobots: the later step waits, or starts and pauses the running one.
        (COBOTS_WAIT, "c2", AreaRule("c2", "c1", "wait")),
        (COBOTS_PAUSE, "c2", AreaRule("c1", "c2", "pause")),
        (COBOTS_PAUSE, "c1", AreaRule("c2", "c1", "pause")),
        # Operator and cobot, pause: the cobot is paused, or waits when it is the later one.
        (PAUSE, "o1", AreaRule("c1", "o1", "pause")),
        (PAUSE, "c1", AreaRule("c1", "o1", "wait")),
        # Slow: whoever comes later, the cobot runs slowly while the operator is there.
        (SLOW, "o1", AreaRule("c1", "o1", "slow")),
        (SLOW, "c1", AreaRule("c1", "o1", "slow")),
    ],
)
def test_who_waits_and_who_is_interrupted(pair: SpacePair, entering: str, rule: AreaRule) -> None:
    assert entering_area(pair, entering) == rule


def test_only_a_refusal_or_a_wait_keeps_the_task_out() -> None:
    assert [m for m in ("refused", "wait", "pause", "slow") if AreaRule("a", "b", m).keeps_out] == [
        "refused",
        "wait",
    ]


def test_space_rules_name_each_partner_of_the_entering_task() -> None:
    net = _two_of("cobot", "cobot")

    assert net.space_rules("b1") == [AreaRule("b1", "a1", "wait")]
    assert net.space_rules("elsewhere") == []
