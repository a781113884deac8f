"""Gateways that need the whole process read first: inclusive blocks and deferred choices."""

from collections.abc import Callable

from hrc.engine.bpmn_net import MAX_INCLUSIVE_BRANCHES, Flow, FlowNode


def deferred_choices(nodes: list[FlowNode]) -> None:
    """An event-based gateway's outgoing flows share one place: its events race for it."""
    for gateway in nodes:
        if gateway.kind != "eventBasedGateway":
            continue
        single = len(gateway.incoming) == 1
        centre = gateway.incoming[0].place if single else gateway.hrc_id
        for flow in gateway.outgoing:
            flow.place = centre


def inclusive_blocks(nodes: list[FlowNode], fail: Callable[..., None]) -> None:
    """Finds each inclusive split's join: the inclusive gateway every branch reaches first.

    Refuses (through `fail`) a split whose branches meet again elsewhere, one
    with too many branches, and a join no split of its block started.
    """
    joins = {n.xml_id for n in nodes if n.kind == "inclusiveGateway" and len(n.incoming) > 1}
    claimed: set[str] = set()
    for split in [n for n in nodes if n.kind == "inclusiveGateway" and len(n.outgoing) > 1]:
        if len(split.incoming) > 1:
            fail(
                f"The {split.describe()} both joins and splits: draw an inclusive join and "
                "a separate inclusive split.",
                split.xml_id,
            )
            continue
        if len(split.outgoing) > MAX_INCLUSIVE_BRANCHES:
            fail(
                f"The {split.describe()} has {len(split.outgoing)} branches; inclusive "
                f"gateways are imported with at most {MAX_INCLUSIVE_BRANCHES}.",
                split.xml_id,
            )
            continue
        reached = [_reach(flow, joins) for flow in split.outgoing]
        common = set.intersection(*[set(r) for r in reached]) if reached else set()
        if not any(reached):
            continue  # the branches never meet again: no join to tell
        candidates = [j for j in reached[0] if j in common]
        join = next((n for n in nodes if candidates and n.xml_id == candidates[0]), None)
        mapping = _branch_flows(split, join) if join is not None else None
        if join is None or mapping is None:
            fail(
                f"The {split.describe()} splits into branches that do not all meet again at "
                "one inclusive gateway, one flow each: hrc imports inclusive gateways that "
                "form a block.",
                split.xml_id,
            )
            continue
        split.inclusive_join = join
        split.branch_flows = mapping
        claimed.add(join.xml_id)
    for join in [n for n in nodes if n.xml_id in joins and n.xml_id not in claimed]:
        if len(join.outgoing) <= 1:
            fail(
                f"The {join.describe()} merges branches no inclusive split of the same "
                "block started: hrc imports inclusive gateways that form a block.",
                join.xml_id,
            )


def _branch_flows(split: FlowNode, join: FlowNode) -> dict[str, str] | None:
    mapping: dict[str, str] = {}
    for flow in split.outgoing:
        arrivals = _arrivals(flow, join)
        if len(arrivals) != 1:
            return None
        mapping[flow.xml_id] = arrivals[0].place
    if len(set(mapping.values())) != len(join.incoming):
        return None
    return mapping


def _reach(flow: Flow, joins: set[str]) -> list[str]:
    """The joins reachable from the flow without passing another, nearest first."""
    seen: set[int] = set()
    found: list[str] = []
    frontier = [flow]
    while frontier:
        following: list[Flow] = []
        for current in frontier:
            if id(current) in seen:
                continue
            seen.add(id(current))
            target = current.target
            if target.xml_id in joins:
                if target.xml_id not in found:
                    found.append(target.xml_id)
                continue
            following += target.outgoing
        frontier = following
    return found


def _arrivals(flow: Flow, join: FlowNode) -> list[Flow]:
    """The join's incoming flows reachable from the flow."""
    seen: set[int] = set()
    arrivals: list[Flow] = []
    stack = [flow]
    while stack:
        current = stack.pop()
        if id(current) in seen:
            continue
        seen.add(id(current))
        if current.target is join:
            if current not in arrivals:
                arrivals.append(current)
            continue
        stack += current.target.outgoing
    return arrivals
