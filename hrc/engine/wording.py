"""Elements named as the engineer drew them, for check messages.

A task or place is named by its label where it has one (“pick insert”) and by
its id otherwise (task tc1), so a message reads like the drawing; the issue
still carries the ids, which the editor highlights.
"""

from collections.abc import Iterable

from hrc.engine.model import Pattern


class Names:
    def __init__(self, pattern: Pattern) -> None:
        self.pattern = pattern
        self.labels: dict[str, str] = {}
        self.tasks: set[str] = set()
        self.places: set[str] = set()
        self.timers: set[str] = set()
        self.cancels: dict[str, list[str]] = {}
        for process in pattern.processes:
            for place in process.places:
                self.places.add(place.id)
                label = place.extra.get("label")
                if isinstance(label, str) and label.strip():
                    self.labels[place.id] = label.strip()
            for transition in process.transitions:
                self.tasks.add(transition.id)
                if transition.label and transition.label.strip():
                    self.labels[transition.id] = transition.label.strip()
                if transition.is_task:
                    continue
                if "timer" in transition.extra:
                    self.timers.add(transition.id)
                cancels = transition.extra.get("cancels")
                if isinstance(cancels, list) and cancels:
                    self.cancels[transition.id] = [c for c in cancels if isinstance(c, str)]

    def name(self, element_id: str) -> str:
        """“pick insert” for a labelled task or place, its id otherwise."""
        label = self.labels.get(element_id)
        return f"“{label}”" if label else element_id

    def task(self, task_id: str) -> str:
        label = self.labels.get(task_id)
        return f"“{label}”" if label else f"task {task_id}"

    def place(self, place_id: str) -> str:
        label = self.labels.get(place_id)
        return f"place “{label}”" if label else f"place {place_id}"

    def actor(self, actor_id: str) -> str:
        """`operator o`, `cobot c`; an undeclared actor is `actor 'x'`."""
        actor = self.pattern.actor(actor_id)
        return f"{actor.type} {actor_id}" if actor else f"actor {actor_id!r}"

    def process(self, process_id: str) -> str:
        """`the drawing` when the pattern has one process, else `process N`."""
        return "the drawing" if len(self.pattern.processes) == 1 else f"process {process_id}"

    def node(self, element_id: str) -> str:
        """A place or task by what it is; an id of neither is quoted."""
        if element_id in self.tasks:
            transition = self.pattern.transition(element_id)
            if transition is not None and not transition.is_task:
                kind = "timer" if element_id in self.timers else "split/join"
                return f"{kind} {self.name(element_id)}"
            return self.task(element_id)
        if element_id in self.places:
            return self.place(element_id)
        return repr(element_id)

    def nodes(self, element_ids: Iterable[str], limit: int = 8) -> str:
        named = [self.node(e) for e in element_ids]
        if len(named) <= limit:
            return _joined(named)
        return f"{', '.join(named[:limit])} and {len(named) - limit} more"

    def firing(self, kind: str, task_id: str) -> str:
        """A step of a firing sequence: `“pick insert” starts`, `“pick insert” completes`,
        `split/join t1 fires`, `timer t2 rings and cancels task tc1`."""
        if kind == "start":
            return f"{self.task(task_id)} starts"
        if kind == "complete":
            return f"{self.task(task_id)} completes"
        step = f"{self.node(task_id)} {'rings' if task_id in self.timers else 'fires'}"
        if task_id in self.cancels:
            step += f" and cancels {self.nodes(self.cancels[task_id], limit=3)}"
        return step


def sentence(text: str) -> str:
    """The text with its first letter capital (str.capitalize would lower the rest)."""
    return text[:1].upper() + text[1:]


def _joined(words: list[str]) -> str:
    if len(words) <= 1:
        return "".join(words) or "none"
    return f"{', '.join(words[:-1])} and {words[-1]}"
