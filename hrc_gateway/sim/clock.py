"""Robot time: every duration the simulator waits is robot seconds, scaled to wall time.

`time_scale` 1.0 runs in real time, 0.05 twenty times faster, and 0 makes
every duration zero (a step then costs only its computation, for benchmarks).
"""

from __future__ import annotations

import asyncio
import math

# The controller samples motion at ~25 Hz of robot time...
SAMPLE_PERIOD = 0.04
# ...but never more often than every 10 ms of wall time, whatever the scale.
MIN_WALL_PERIOD = 0.01


class Clock:
    """Scales robot seconds to wall seconds."""

    def __init__(self, time_scale: float = 1.0) -> None:
        if not math.isfinite(time_scale) or time_scale < 0:
            raise ValueError(f"time_scale must be a finite number ≥ 0, not {time_scale}")
        self.time_scale = time_scale

    @property
    def instant(self) -> bool:
        """True when durations are zero: motion jumps to its end."""
        return self.time_scale == 0

    @property
    def sample_period(self) -> float:
        """Wall seconds between two motion samples."""
        return max(SAMPLE_PERIOD * self.time_scale, MIN_WALL_PERIOD)

    def robot_seconds(self, wall_seconds: float) -> float:
        """How much robot time `wall_seconds` of wall time stand for (not defined when instant)."""
        return wall_seconds / self.time_scale

    def now(self) -> float:
        """Wall time (the event loop's monotonic clock)."""
        return asyncio.get_running_loop().time()

    async def sleep(self, seconds: float) -> None:
        """Waits `seconds` of robot time; at scale 0 it only yields to other tasks."""
        await asyncio.sleep(max(seconds, 0.0) * self.time_scale)
