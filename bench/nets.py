"""Generated `hrc-pattern/1` documents for the soundness benchmark.

Each family grows one kind of state space, so the table shows how a checker
scales with the shape of the model and not only with its size:

- `blocks`: a chain of AND blocks (split, two short task chains, join); the
  state space grows linearly with the size.
- `wide-2`, `wide-3`: one AND-split into 2 / 3 long chains; about (n/k)^k
  markings, the worst case of interleaving.
- `lanes`: an operator lane and a cobot lane in parallel, with a time
  constraint from operator task i to cobot task i+1 every 3 tasks (the
  Synchronized shape of the thesis).
- `lanes-dead`: `lanes` plus two time constraints that contradict each other
  (the middle operator task needs the last cobot task and the middle cobot
  task needs the last operator task), so both lanes deadlock half-way.

`transitions` counts the pattern's transitions, silent splits and joins
included, and every generator hits it exactly. Every document is valid under
the rules of pattern-format.md (every actor performs a task, every constraint
joins tasks of different performers), so the checkers measure behaviour and
not a rule violation that stops them early.
"""

from collections.abc import Callable
from typing import Any

Document = dict[str, Any]

FAMILIES: tuple[str, ...] = ("blocks", "wide-2", "wide-3", "choices-3", "lanes", "lanes-dead")
SIZES: tuple[int, ...] = (20, 100, 200)
# The program the generated cobots' tasks run: step 1 of pick-and-place moves home.
PROGRAM = "Coexistence_PickAndPlace"

# Tasks per branch of a `blocks` block before the remainder is spread: short
# chains keep the state space linear while each block still interleaves.
BLOCK_BRANCH_TASKS = 2
# `lanes`: a time constraint from operator task i to cobot task i+1 for every
# i that is a multiple of this.
LANE_CONSTRAINT_EVERY = 3


class _Builder:
    """Collects one process' places, transitions and arcs with ids unique in the document."""

    def __init__(self) -> None:
        self.places: list[dict[str, Any]] = []
        self.transitions: list[dict[str, Any]] = []
        self.arcs: list[list[str]] = []
        self._places = 0
        self._tasks = 0

    def place(self, tokens: int | None = None) -> str:
        self._places += 1
        place_id = f"p{self._places}"
        place: dict[str, Any] = {"id": place_id}
        if tokens is not None:
            place["tokens"] = tokens
        self.places.append(place)
        return place_id

    def silent(self, transition_id: str) -> str:
        self.transitions.append({"id": transition_id})
        return transition_id

    def task(self, performer: str) -> str:
        self._tasks += 1
        task_id = f"t{self._tasks}"
        self.transitions.append(
            {"id": task_id, "performer": performer, "label": f"{performer} step {self._tasks}"}
        )
        return task_id

    def arc(self, source: str, target: str) -> None:
        self.arcs.append([source, target])

    def chain(self, start: str, performer: str, length: int) -> tuple[str, list[str]]:
        """`length` tasks in sequence after place `start`; returns the last place and the tasks."""
        place = start
        tasks = []
        for _ in range(length):
            task = self.task(performer)
            self.arc(place, task)
            place = self.place()
            self.arc(task, place)
            tasks.append(task)
        return place, tasks


def _spread(total: int, parts: int) -> list[int]:
    """`total` split into `parts` near-equal whole numbers, larger ones first."""
    base, extra = divmod(total, parts)
    return [base + (1 if index < extra else 0) for index in range(parts)]


def _actors(count: int) -> list[dict[str, str]]:
    """`count` actors alternating operator and cobot, so each parallel branch has its own;
    each cobot names the program its tasks run (a cobot task without one does not check)."""
    actors = []
    for index in range(count):
        if index % 2 == 0:
            actors.append({"id": f"op{index // 2 + 1}", "type": "operator"})
        else:
            actors.append({"id": f"cobot{index // 2 + 1}", "type": "cobot", "program": PROGRAM})
    return actors


def _document(
    name: str,
    actors: list[dict[str, str]],
    builder: _Builder,
    constraints: list[dict[str, str]] | None = None,
) -> Document:
    return {
        "format": "hrc-pattern/1",
        "name": name,
        "actors": actors,
        "processes": [
            {
                "id": "N",
                "workpiece": "w",
                "actors": [actor["id"] for actor in actors],
                "places": builder.places,
                "transitions": builder.transitions,
                "arcs": builder.arcs,
            }
        ],
        "constraints": constraints or [],
    }


def _parallel(builder: _Builder, start: str, index: int, chains: list[tuple[str, int]]) -> str:
    """An AND-split after `start` into chains (performer, length) and their AND-join.

    Returns the place after the join.
    """
    split = builder.silent(f"split{index}")
    builder.arc(start, split)
    join = builder.silent(f"join{index}")
    for performer, length in chains:
        first = builder.place()
        builder.arc(split, first)
        last, _ = builder.chain(first, performer, length)
        builder.arc(last, join)
    after = builder.place()
    builder.arc(join, after)
    return after


def blocks(transitions: int) -> Document:
    """A chain of AND blocks, each split → operator chain ∥ cobot chain → join."""
    per_block = 2 + 2 * BLOCK_BRANCH_TASKS
    count = max(1, transitions // per_block)
    if transitions < 4:
        raise ValueError("blocks needs at least 4 transitions (split, two tasks, join)")
    # The transitions a whole number of blocks leaves over go into the branches,
    # one at a time from the front, so the count is exact.
    branch_lengths = _spread(transitions - 2 * count, 2 * count)
    actors = _actors(2)
    builder = _Builder()
    place = builder.place(tokens=1)
    for block in range(count):
        operator_tasks, cobot_tasks = branch_lengths[2 * block], branch_lengths[2 * block + 1]
        chains = [(actors[0]["id"], operator_tasks), (actors[1]["id"], cobot_tasks)]
        place = _parallel(builder, place, block + 1, chains)
    return _document(f"blocks-{transitions}", actors, builder)


def wide(transitions: int, width: int) -> Document:
    """One AND-split into `width` chains, one actor each, and their AND-join."""
    if transitions < 2 + width:
        raise ValueError(f"wide-{width} needs at least {2 + width} transitions")
    actors = _actors(width)
    builder = _Builder()
    start = builder.place(tokens=1)
    lengths = _spread(transitions - 2, width)
    _parallel(
        builder, start, 1, [(actor["id"], n) for actor, n in zip(actors, lengths, strict=True)]
    )
    return _document(f"wide-{width}-{transitions}", actors, builder)


def choices(transitions: int, width: int) -> Document:
    """One AND-split into `width` chains of exclusive choices (two alternative tasks a step).

    The structural reduction cannot fold a choice away, so every chain keeps
    one state per step and the markings multiply across chains: this family
    measures the state-space search itself, not the reduction.
    """
    if transitions < 2 + 2 * width:
        raise ValueError(f"choices-{width} needs at least {2 + 2 * width} transitions")
    actors = _actors(width)
    builder = _Builder()
    start = builder.place(tokens=1)
    split, join = builder.silent("split1"), builder.silent("join1")
    builder.arc(start, split)
    for actor, count in zip(actors, _spread(transitions - 2, width), strict=True):
        place = builder.place()
        builder.arc(split, place)
        steps = _spread(count, (count + 1) // 2)  # 2 alternatives a step; a lone 1 if odd
        for alternatives in steps:
            after = builder.place()
            for _ in range(alternatives):
                task = builder.task(actor["id"])
                builder.arc(place, task)
                builder.arc(task, after)
            place = after
        builder.arc(place, join)
    builder.arc(join, builder.place())
    return _document(f"choices-{width}-{transitions}", actors, builder)


def _lane_net(transitions: int) -> tuple[list[dict[str, str]], _Builder, list[str], list[str]]:
    """The two lanes: split → operator lane ∥ cobot lane → join; returns both lanes' tasks."""
    if transitions < 6:
        raise ValueError("lanes needs at least 6 transitions (split, 2 + 2 tasks, join)")
    actors = _actors(2)
    builder = _Builder()
    start = builder.place(tokens=1)
    operator_length, cobot_length = _spread(transitions - 2, 2)
    split = builder.silent("split1")
    builder.arc(start, split)
    join = builder.silent("join1")
    lanes = []
    for actor, length in ((actors[0], operator_length), (actors[1], cobot_length)):
        first = builder.place()
        builder.arc(split, first)
        last, tasks = builder.chain(first, actor["id"], length)
        builder.arc(last, join)
        lanes.append(tasks)
    end = builder.place()
    builder.arc(join, end)
    return actors, builder, lanes[0], lanes[1]


def _time(source: str, target: str) -> dict[str, str]:
    return {"from": source, "to": target, "type": "time"}


def lanes(transitions: int) -> Document:
    """Operator lane ∥ cobot lane, cobot task i+1 after operator task i every 3 tasks."""
    actors, builder, operator, cobot = _lane_net(transitions)
    constraints = [
        _time(operator[i], cobot[i + 1])
        for i in range(0, len(operator), LANE_CONSTRAINT_EVERY)
        if i + 1 < len(cobot)
    ]
    return _document(f"lanes-{transitions}", actors, builder, constraints)


def lanes_dead(transitions: int) -> Document:
    """`lanes` with two contradicting time constraints: both lanes wait for each other's end.

    The constrained tasks are in the middle of the lanes (not the first ones)
    so a checker explores a real state space before it meets the deadlock,
    and the tasks after them are dead.
    """
    document = lanes(transitions)
    process = document["processes"][0]
    by_performer: dict[str, list[str]] = {}
    for transition in process["transitions"]:
        if "performer" in transition:
            by_performer.setdefault(transition["performer"], []).append(transition["id"])
    operator, cobot = (by_performer[actor["id"]] for actor in document["actors"])
    document["constraints"] += [
        _time(cobot[-1], operator[len(operator) // 2]),
        _time(operator[-1], cobot[len(cobot) // 2]),
    ]
    document["name"] = f"lanes-dead-{transitions}"
    return document


GENERATORS: dict[str, Callable[[int], Document]] = {
    "blocks": blocks,
    "wide-2": lambda transitions: wide(transitions, 2),
    "wide-3": lambda transitions: wide(transitions, 3),
    "lanes": lanes,
    "lanes-dead": lanes_dead,
    "choices-3": lambda transitions: choices(transitions, 3),
}

# Families whose every run ends properly; `lanes-dead` deadlocks by construction.
EXPECTED_SOUND: dict[str, bool] = {family: family != "lanes-dead" for family in FAMILIES}


def generate(family: str, transitions: int) -> Document:
    """The document of one family at a given transition count (splits and joins included)."""
    try:
        generator = GENERATORS[family]
    except KeyError:
        raise ValueError(f"unknown family {family!r}; one of {', '.join(FAMILIES)}") from None
    return generator(transitions)


def transition_count(document: Document) -> int:
    return sum(len(process["transitions"]) for process in document["processes"])
