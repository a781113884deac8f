"""What the cobots app learns from, and tells, the apps above it, through functions they register.

Imports point inwards: cases and live import cobots, never the other way. Yet
only the cases app knows whether a case is using a cobot, how long its queue
is, whether an operator's interruption holds it, and how to start its next
job; only the live app tells the tablets. Each app registers its answers in
its receivers.py (loaded by its AppConfig.ready()). Asking cases before it
has answered is a configuration error, never a silent "free"; telling the
tablets with no live app installed does nothing.
"""

from __future__ import annotations

from collections.abc import Callable, Collection
from dataclasses import dataclass
from typing import Any

from django.core.exceptions import ImproperlyConfigured

from hrc.cobots.models import CellStop

# The reason a case is using the cobot, as a sentence; "" when it is free.
InUse = Callable[[int], str]
# The number of jobs each cobot has still to do or is doing, by cobot id (absent: none).
QueueLengths = Callable[[Collection[int]], dict[int, int]]
# Whether an operator's interruption (a space constraint) still keeps the cobot paused.
HeldByInterruption = Callable[[int], bool]
# The cobot's queue may go on (a STOP ended): start its next job after commit, if one waits.
QueueReleased = Callable[[int], None]
# Each device's queued and running calls in queue order, by device id (absent: none); each a
# dict with "case", "label", "state" and "waiting_for".
DeviceQueues = Callable[[Collection[int]], dict[int, list[dict[str, Any]]]]
# The devices' queues may go on (their cell's STOP ended): start their next calls after commit.
DevicesReleased = Callable[[Collection[int]], None]
# Tell the tablets after commit: the cobot's queue changed / a STOP began, changed or ended.
QueueChanged = Callable[[int], None]
StopChanged = Callable[[CellStop], None]


@dataclass
class _CobotUse:
    in_use: InUse | None = None
    queue_lengths: QueueLengths | None = None
    held_by_interruption: HeldByInterruption | None = None
    queue_released: QueueReleased | None = None
    queue_changed: QueueChanged | None = None
    stop_changed: StopChanged | None = None
    devices_released: DevicesReleased | None = None
    device_queues: DeviceQueues | None = None


_REGISTERED = _CobotUse()


def register_cobot_use(*, in_use: InUse, queue_lengths: QueueLengths) -> None:
    """Called once by the app that runs cases, from its receivers.py."""
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


# STOP and resume (hrc.cobots.stops) --------------------------------------------------------


def register_cobot_queues(
    *, held_by_interruption: HeldByInterruption, queue_released: QueueReleased
) -> None:
    """Called once by the app that runs cases, from its receivers."""
    _REGISTERED.held_by_interruption = held_by_interruption
    _REGISTERED.queue_released = queue_released


def register_device_queues(
    *, devices_released: DevicesReleased, device_queues: DeviceQueues
) -> None:
    """Called once by the app that runs cases, from its receivers."""
    _REGISTERED.devices_released = devices_released
    _REGISTERED.device_queues = device_queues


def device_queues(device_ids: Collection[int]) -> dict[int, list[dict[str, Any]]]:
    """The devices' queues by id ([] for those with none)."""
    if _REGISTERED.device_queues is None:
        raise ImproperlyConfigured("No app has registered device_queues (hrc.cases does).")
    queues = _REGISTERED.device_queues(device_ids)
    return {device_id: queues.get(device_id, []) for device_id in device_ids}


def devices_released(device_ids: Collection[int]) -> None:
    """Starts the devices' next queued calls once the transaction commits, if any wait."""
    if _REGISTERED.devices_released is None:
        raise ImproperlyConfigured("No app has registered devices_released (hrc.cases does).")
    _REGISTERED.devices_released(device_ids)


def register_tablets(*, queue_changed: QueueChanged, stop_changed: StopChanged) -> None:
    """Called once by the app that serves the tablets, from its receivers."""
    _REGISTERED.queue_changed = queue_changed
    _REGISTERED.stop_changed = stop_changed


def held_by_interruption(cobot_id: int) -> bool:
    """Whether an operator in a shared area still keeps the cobot paused."""
    if _REGISTERED.held_by_interruption is None:
        raise ImproperlyConfigured("No app has registered held_by_interruption (hrc.cases does).")
    return _REGISTERED.held_by_interruption(cobot_id)


def queue_released(cobot_id: int) -> None:
    """Starts the cobot's next queued job once the transaction commits, if one waits."""
    if _REGISTERED.queue_released is None:
        raise ImproperlyConfigured("No app has registered queue_released (hrc.cases does).")
    _REGISTERED.queue_released(cobot_id)


def queue_changed(cobot_id: int) -> None:
    """Tells the tablets, once the transaction commits, that the cobot's queue changed."""
    if _REGISTERED.queue_changed is not None:
        _REGISTERED.queue_changed(cobot_id)


def stop_changed(stop: CellStop) -> None:
    """Shows the STOP on the tablets as it is once the transaction commits."""
    if _REGISTERED.stop_changed is not None:
        _REGISTERED.stop_changed(stop)
