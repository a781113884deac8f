"""How much a check may spend: markings held in memory and seconds of CPU.

A pattern of twenty parallel lanes fits in 20 KB and has millions of
reachable markings, so the state-space analysis must stop somewhere. A
`Budget` says where: at `max_markings` markings (each costs about a
kilobyte with its edges) and at `seconds` after the check started. The
caller chooses it (a request checks within a small one, a background
worker within a larger one) and passes a clock in, so a test can make time
pass without waiting and the engine reads no settings.

Every phase whose cost grows with the state space (exploration with its
cover test, the per-marking fault scan, the backward search for livelocks)
asks the same `Deadline`; when it has passed, what was found stays
reported and the verdict becomes "too large to decide in N s".
"""

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field

DEFAULT_MAX_MARKINGS = 200_000

Clock = Callable[[], float]


@dataclass(frozen=True)
class Budget:
    """The most a check may explore; `seconds=None` puts no limit on time."""

    max_markings: int = DEFAULT_MAX_MARKINGS
    seconds: float | None = None
    clock: Clock = field(default=time.monotonic, compare=False, repr=False)

    def start(self) -> "Deadline":
        """The deadline of a check that starts now."""
        end = math.inf if self.seconds is None else self.clock() + self.seconds
        return Deadline(self.clock, end)


NO_TIME_LIMIT = Budget()
"""The default: DEFAULT_MAX_MARKINGS and no deadline (the command line, the runtime's own checks)."""


@dataclass(frozen=True)
class Deadline:
    clock: Clock
    end: float

    def passed(self) -> bool:
        return self.end != math.inf and self.clock() >= self.end
