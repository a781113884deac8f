"""What the cobots app learns from the cases app, through functions the cases app registers.

Imports point inwards: cases imports cobots, never the other way. Yet only the
cases app knows whether a case is using a cobot, and how long its queue is.
The cases app registers its answers in its AppConfig.ready()
(hrc.cases.apps); asking before anything is registered is a configuration
error, never a silent "free".
"""

from __future__ import annotations

from collections.abc import Callable, Collection
from dataclasses import dataclass

from django.core.exceptions import ImproperlyConfigured

# The reason a case is using the cobot, as a sentence; "" when it is free.
InUse = Callable[[int], str]
# The number of jobs each cobot has still to do or is doing, by cobot id (absent: none).
QueueLengths = Callable[[Collection[int]], dict[int, int]]


@dataclass
class _CobotUse:
    in_use: InUse | None = None
    queue_lengths: QueueLengths | None = None


_REGISTERED = _CobotUse()


def register_cobot_use(*, in_use: InUse, queue_lengths: QueueLengths) -> None:
    """Called once by the app that runs cases, from its AppConfig.ready()."""
    _REGISTERED.in_use = in_use
    _REGISTERED.queue_lengths = queue_lengths


def cobot_in_use(cobot_id: int) -> str:
    """Why a case is using the cobot ("" when none is); ImproperlyConfigured if nobody answers."""
    if _REGISTERED.in_use is None:
        raise ImproperlyConfigured("No app has registered cobot_in_use (hrc.cases does).")
    return _REGISTERED.in_use(cobot_id)


def queue_lengths(cobot_ids: Collection[int]) -> dict[int, int]:
    """The cobots' queue lengths by id, 0 for those with none."""
    if _REGISTERED.queue_lengths is None:
        raise ImproperlyConfigured("No app has registered queue_lengths (hrc.cases does).")
    counted = _REGISTERED.queue_lengths(cobot_ids)
    return {cobot_id: counted.get(cobot_id, 0) for cobot_id in cobot_ids}
