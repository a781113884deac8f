"""Graph search shared by the structural rules and the state-space analysis."""

from collections import deque
from collections.abc import Hashable, Iterable, Mapping
from typing import TypeVar

Node = TypeVar("Node", bound=Hashable)


def reachable(starts: Iterable[Node], successors: Mapping[Node, Iterable[Node]]) -> set[Node]:
    """Every node reachable from `starts` (included) along `successors`; absent keys have none."""
    reached = set(starts)
    queue = deque(reached)
    while queue:
        for successor in successors.get(queue.popleft(), ()):
            if successor not in reached:
                reached.add(successor)
                queue.append(successor)
    return reached
