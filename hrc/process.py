"""Once a long-running process has started, what it loaded leaves the garbage collector's sight.

A full collection walks every object the collector tracks. Once Django, DRF,
Channels, Celery and asyncua are imported that is about 165 000 objects, and
a walk takes 70–100 ms on a 2-core machine: a stall in the middle of whatever
request or step the process was serving, and what set the p99 and the
maximum of `make bench`'s step signalling. Those objects live as long as the
process anyway. `gc.freeze()` moves them where no collection looks, so later
ones walk only what came after (Instagram's remedy for Django; gunicorn's
docs give it too).
"""

import gc


def freeze_start_up() -> None:
    """Collects the start-up's garbage, then freezes everything that is left."""
    gc.collect()
    gc.freeze()
