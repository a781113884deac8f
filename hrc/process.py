"""Once a long-running process has started, what it loaded leaves the garbage collector's sight.

A full collection walks every object the collector tracks, and after Django, DRF, Channels,
Celery and asyncua are imported that walk is a stall in the middle of a request or a cobot
step. Those objects live as long as the process anyway, so `gc.freeze()` moves them where
no collection looks (Instagram's remedy for Django). What the walk cost: bench/README.md.
"""

import gc


def freeze_start_up() -> None:
    """Collects the start-up's garbage, then freezes everything that is left."""
    gc.collect()
    gc.freeze()
