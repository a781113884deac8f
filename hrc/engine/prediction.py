"""Predicting a pattern before it runs: cycle time, each actor's load, waiting, the bottleneck.

`predict(net, scenario)` is a discrete-event simulation of `scenario.cases` cases,
`scenario.parallel` of them in flight at once (all start at time 0; each case that
ends is replaced by the next until all have started), over the runtime's own firing
rule: every start, completion and silent firing is `CaseNet`'s, so the markings, the
constraint places, guards, messages, timers and cancels are the runtime's. What the
runtime's rows and workers (hrc.cases) add, it models as they do it:

- Operators: each operator actor, or the stand-in a case variant names, is a team of
  `people` persons (1 unless the scenario says; None: as many as there is work, like
  `run_pattern --simulate`'s operators). A free person takes the team's oldest offered
  task (first come, first served) and completes it after its sampled time. At one instant
  the cobots and devices take their work first (a completion leases the step it enables;
  a tablet polls after).
- Cobots: one queue each, ordered by offer time (a job's `queued_at`). A free cobot takes
  the first queued step that may start now, passing over one that must wait (a shared
  area, another case's func hold), and the step's task starts then. Each device (a
  device actor, or each kind of device a cobot actor calls) is a queue of its own.
- time and func constraints are places of the net. A step done while a func constraint
  holds its completion holds its cobot for its case: other cases' steps wait, its own may
  go. An operator whose completion is held completes the moment the constraint allows
  (the tablet refuses before, the person tries again).
- space constraints follow `entering_area`: a kept-out task waits until the task in the
  area completes; a paused step's time stops (and its cobot takes no other step) until
  the task that paused it completes; a slowed step runs at `slow_rate`. (A cancelled
  operator's task leaves the area at once; at run time a person confirms it.)
- Choices between silent transitions: by `weights` (transition id → weight) where any of
  the competing transitions has one (one without a weight is then never taken); else by
  the guards over the case data, the first in net order whose guard holds (settle's
  rule); where none of them has a guard, uniformly. A deferred choice between tasks goes
  to the first started (as at run time), or by `weights` where its tasks have them.
- Case data: the pattern's, under the case variant's, changed by each task's outputs as
  at run time. Results are what a simulated plant gives: an operator answers its form
  as `run_pattern --simulate`'s operators do (forms.example_answers), a step gives
  {"outcome": "ran", "seconds": …}, a device call what the `plant` answers, else its happy
  answer (a gesture seen, a face authorised, every screw found, the place free, an
  inspection "ok"; a loop left only on an unhappy answer then needs weights).
- Messages travel within a case (between its processes); a case waiting for a message
  no process of its own sends is stuck. Timers ring after their time × `timer_scale`.

Task times: `scenario.durations` by task id; else a cobot or device task asks the
`plant` (the program's simulated time), when one is given; else `operator_default` or
`cobot_default` (reported as `assumed`). Everything random draws from one
`random.Random(seed)` in event order: the same inputs and seed give the same prediction.

A case that cannot end (nothing it waits for can happen, a guard or output fails, or
it runs more than `max_tasks_per_case` tasks) is reported in `stuck`, never run forever.

What a prediction reports, and how the critical path and the bottleneck are defined, is
prediction_report.py's; `scenario_from_dict` reads a scenario from JSON (the API's).
"""

from __future__ import annotations

import math
import random
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any, Final, Protocol

from hrc.engine.durations import Duration, DurationError, Fixed, duration_from_dict
from hrc.engine.prediction_report import Prediction
from hrc.engine.prediction_run import Simulation
from hrc.engine.runtime import CaseNet

# What an operator's task and a cobot's step take when no time is given and no plant knows.
DEFAULT_OPERATOR_TIME: Final = Fixed(30.0)
DEFAULT_COBOT_TIME: Final = Fixed(10.0)
# The speed override a space constraint's "slow" sets (hrc.cases.interruptions).
SLOW_RATE: Final = 0.1


class Plant(Protocol):
    """The cobots and devices a prediction runs against: how long a command takes, and what a
    device call answers (hrc_gateway.sim.timing.SimulatedPlant: the simulator's programs
    and devices). A plant may follow each arm from step to step: it is asked as each step
    starts, in start order per cobot, and a prediction makes its own (`predict`'s `plant`)."""

    def seconds(self, cobot: str, command: Mapping[str, Any], at: float) -> float | None:
        """Seconds at full speed for `command` (commands.cobot_command's: a step or a device
        call) on `cobot` (a cobot or device actor, or its stand-in; a cobot actor's device
        "<cobot>.<kind>") starting `at` (the prediction's clock, seconds); None when the plant
        cannot tell (the scenario's default is taken)."""
        ...

    def answer(
        self, cobot: str, command: Mapping[str, Any], rng: random.Random, at: float
    ) -> Mapping[str, Any] | None:
        """A device call's outputs by name (DeviceConfig.output_names) as it ends `at`, drawn
        from `rng` (the prediction's, so that the seed decides); None for the happy answer."""
        ...


@dataclass(frozen=True)
class CaseVariant:
    """How one case differs from the pattern's defaults: its data laid over the pattern's, and
    who stands in for an actor (another actor of its type, or a new name: a team or cobot of
    its own). The document's `"simulation": {"cases": […]}` says the same (case_variants)."""

    name: str
    data: Mapping[str, Any] = field(default_factory=dict)
    actors: Mapping[str, str] = field(default_factory=dict)


@dataclass(frozen=True)
class Scenario:
    """What to predict: how many cases, how many at once, the times, the people and choices."""

    cases: int = 1000
    parallel: int = 1
    seed: int = 0
    durations: Mapping[str, Duration] = field(default_factory=dict)
    """Task id → its time."""
    operator_default: Duration = DEFAULT_OPERATOR_TIME
    cobot_default: Duration = DEFAULT_COBOT_TIME
    people: Mapping[str, int | None] = field(default_factory=dict)
    """Operator actor (or stand-in) → persons in its team; 1 when not given, None: unlimited."""
    weights: Mapping[str, float] = field(default_factory=dict)
    """Transition id → its weight among the transitions it competes with."""
    variants: tuple[CaseVariant, ...] | None = None
    """Case i is variants[i mod len]; None: the pattern's own (`simulation.cases`), if any."""
    timer_scale: float = 1.0
    slow_rate: float = SLOW_RATE
    handover: float = 0.0
    """Seconds from a task's start (its person or cobot taken) to its work beginning: a
    tablet's poll, a worker's lease. Its shared area is entered after them."""
    max_tasks_per_case: int = 1000
    trace: bool = False
    """Record every start and completion (for tests that compare orders)."""

    def __post_init__(self) -> None:
        if self.cases < 0 or self.parallel < 1 or self.max_tasks_per_case < 1:
            raise ValueError("a scenario needs cases ≥ 0, parallel ≥ 1 and max_tasks_per_case ≥ 1.")  # fmt: skip
        if any(not 0 <= w < math.inf for w in self.weights.values()):
            raise ValueError("a choice's weights must be finite numbers ≥ 0.")
        if any(p is not None and p < 1 for p in self.people.values()):
            raise ValueError("a team has at least one person (or None: unlimited).")
        if not (0 < self.timer_scale < math.inf and 0 < self.slow_rate <= 1):
            raise ValueError("a scenario needs timer_scale > 0 and 0 < slow_rate ≤ 1.")
        if not 0 <= self.handover < math.inf:
            raise ValueError("a scenario's handover is a finite number of seconds ≥ 0.")


def predict(
    net: CaseNet,
    scenario: Scenario = Scenario(),
    *,
    plant: Callable[[], Plant] | None = None,
) -> Prediction:
    """Simulates the scenario over `net` (see the module's docstring); `plant` makes the plant
    that times cobot and device tasks without a given time and answers device calls, one per
    prediction.

    Raises ValueError for a case variant that names an unknown actor or one of another type."""
    variants = scenario.variants
    if variants is None:
        variants = case_variants(net.pattern.extra.get("simulation"), net)
    for variant in variants:
        check_variant(variant, net)
    return Simulation(net, scenario, variants, plant() if plant else None).run()


def case_variants(simulation: object, net: CaseNet) -> tuple[CaseVariant, ...]:
    """The variants a document's `"simulation"` object lists (`{"cases": [{"name", "data",
    "actors"}]}`, as `run_pattern --simulate` reads it); () without one. Raises ValueError
    saying what is wrong with its shape (`predict` checks the actors)."""
    if simulation is None:
        return ()
    cases = simulation.get("cases", []) if isinstance(simulation, Mapping) else None
    if not isinstance(cases, list):
        raise ValueError('"simulation" must be an object whose "cases" is a list.')
    variants = []
    for index, case in enumerate(cases, start=1):
        if not isinstance(case, Mapping):
            raise ValueError(f"simulation case {index} must be an object.")
        data, actors = case.get("data", {}), case.get("actors", {})
        if not isinstance(data, Mapping) or not isinstance(actors, Mapping):
            raise ValueError(f"simulation case {index}: data and actors must be objects.")
        variants.append(
            CaseVariant(str(case.get("name") or f"simulation case {index}"), data, actors)
        )
    return tuple(variants)


def check_variant(variant: CaseVariant, net: CaseNet) -> None:
    """ValueError unless each actor it replaces is the pattern's and its stand-in of its type."""
    types = {actor.id: actor.type for actor in net.pattern.actors}
    for actor, stand_in in variant.actors.items():
        if actor not in types:
            raise ValueError(f"{variant.name}: the pattern has no actor {actor!r}.")
        if types.get(stand_in, types[actor]) != types[actor]:
            raise ValueError(f"{variant.name}: {actor} and {stand_in} are not both {types[actor]}s.")  # fmt: skip


# A scenario as JSON (what the API and the command take) -----------------------------------

_SCENARIO_KEYS: Final = frozenset(
    {
        "cases", "parallel", "seed", "durations", "operator_default", "cobot_default", "people",
        "weights", "variants", "timer_scale", "slow_rate", "max_tasks_per_case", "trace",
        "handover",
    }
)  # fmt: skip


def scenario_from_dict(data: Mapping[str, Any]) -> Scenario:
    """A scenario from JSON: the Scenario's fields by name, each optional; a time as
    durations.duration_from_dict reads it, `durations` by task id, `people` a count or null
    (unlimited), `variants` a list of {"name", "data", "actors"}. Raises ValueError saying what
    is wrong (DurationError for a time)."""
    unknown = sorted(set(data) - _SCENARIO_KEYS)
    if unknown:
        raise ValueError(f"a scenario has no {unknown[0]!r}; it has {', '.join(sorted(_SCENARIO_KEYS))}.")  # fmt: skip
    given: dict[str, Any] = {}
    for key in ("cases", "parallel", "seed", "max_tasks_per_case"):
        if key in data:
            given[key] = _whole(key, data[key])
    for key in ("timer_scale", "slow_rate", "handover"):
        if key in data:
            given[key] = _number(key, data[key])
    if "trace" in data:
        if not isinstance(data["trace"], bool):
            raise ValueError("'trace' must be true or false.")
        given["trace"] = data["trace"]
    for key in ("operator_default", "cobot_default"):
        if key in data:
            given[key] = _duration(key, data[key])
    durations = _object("durations", data.get("durations", {}))
    given["durations"] = {task: _duration(task, time) for task, time in durations.items()}
    people = _object("people", data.get("people", {}))
    given["people"] = {
        team: None if count is None else _whole(f"people of {team}", count)
        for team, count in people.items()
    }
    weights = _object("weights", data.get("weights", {}))
    given["weights"] = {t: _number(f"the weight of {t}", w) for t, w in weights.items()}
    if data.get("variants") is not None:
        given["variants"] = _variants(data["variants"])
    return Scenario(**given)


def _variants(raw: object) -> tuple[CaseVariant, ...]:
    if not isinstance(raw, list):
        raise ValueError("'variants' must be a list of cases.")
    variants = []
    for index, case in enumerate(raw, start=1):
        case = _object(f"variant {index}", case)
        data = _object(f"the data of variant {index}", case.get("data", {}))
        actors = _object(f"the actors of variant {index}", case.get("actors", {}))
        if not all(isinstance(stand_in, str) for stand_in in actors.values()):
            raise ValueError(f"variant {index}: each actor's stand-in is a name.")
        variants.append(CaseVariant(str(case.get("name") or f"variant {index}"), data, actors))
    return tuple(variants)


def _object(what: str, value: object) -> Mapping[str, Any]:
    if not isinstance(value, Mapping):
        raise ValueError(f"{what} must be an object.")
    return value


def _whole(what: str, value: object) -> int:
    if isinstance(value, bool) or not isinstance(value, int):
        raise ValueError(f"{what} must be a whole number, not {value!r}.")
    return value


def _number(what: str, value: object) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise ValueError(f"{what} must be a number, not {value!r}.")
    return float(value)


def _duration(what: str, value: object) -> Duration:
    try:
        return duration_from_dict(_object(f"the time of {what}", value))
    except DurationError as problem:
        raise DurationError(f"{what}: {problem}") from None
