"""The one way anything reaches the tablets: after the transaction commits, through the channel layer.

`send_event_on_commit` is the helper (Zulip's); the case services publish
each case event through `case_event_on_commit`, the jobs and STOPs say a
cobot's queue changed through `cobot_queue_on_commit`. Both build their
payload from the objects the caller holds (hrc.live.payloads), so the hot
path pays no query: the commit hook only hands it to the sender thread
(hrc.live.sender), which reads the changed queues once per batch, a cobot's
at most once per QUEUE_COALESCE_SECONDS.

Groups: `hrc.org.<organisation>` (every delta from the database: cases,
work items, incidents, cobot queues, STOPs), `hrc.user.<user>`,
`hrc.cell.<organisation>` (the gateways' cobot states for tablets of the
whole floor) and `hrc.cell.<organisation>.<cell>` (those of one cell's
cobots). The consumer re-checks each message against the socket's user.
"""

from __future__ import annotations

import asyncio
from collections.abc import Iterable, Mapping
from typing import Any

from django.contrib.auth.models import User
from django.db import transaction

from hrc.cases.models import Case, WorkItem
from hrc.cobots.models import CellStop
from hrc.live import payloads, selectors, sender
from hrc.live.events import CobotStateData, LiveEvent
from hrc.live.sender import FLUSH_TIMEOUT, Hold


def organisation_group(organisation_id: int) -> str:
    return f"hrc.org.{organisation_id}"


def user_group(user_id: int) -> str:
    return f"hrc.user.{user_id}"


def cell_groups(organisation_id: int, cell: str) -> list[str]:
    """Where a cobot's deltas go: the whole floor's tablets, and its cell's when it has one."""
    floor = f"hrc.cell.{organisation_id}"
    return [floor, f"{floor}.{cell}"] if cell else [floor]


def cell_group(organisation_id: int, cell: str) -> str:
    """The group a tablet of `cell` ("" for the whole floor) joins."""
    return cell_groups(organisation_id, cell)[-1]


# After commit ---------------------------------------------------------------------------


def send_event_on_commit(
    groups: Iterable[str], event: LiveEvent, *, organisation: int, cell: str = ""
) -> None:
    """Sends `event` to `groups` once the transaction commits; nothing when it rolls back.

    `organisation` and `cell` say whose it is: the consumer checks them against
    the socket before sending. Outside a transaction it is sent at once.
    """
    send = sender.Send(list(groups), organisation, [event], [cell])
    transaction.on_commit(lambda: _sender().put(send))


def case_event_on_commit(
    case: Case,
    event: str,
    item: WorkItem | None,
    user: User | None,
    detail: Mapping[str, Any] | None,
) -> None:
    """The delta for a case event just recorded (case.last_seq is its number). No query.

    Call from record_event, while holding the case row lock.
    """
    delta = payloads.case_delta(case, event, item, user, detail)
    organisation = case.organisation_id
    send_event_on_commit([organisation_group(organisation)], delta, organisation=organisation)
    if item is not None and item.cobot_id is not None and item.kind != "operator":
        cobot_queue_on_commit(item.cobot_id)


def cobot_queue_on_commit(cobot_id: int) -> None:
    """Says, after commit, that the cobot's queue changed; the sender reads it and sends it."""
    transaction.on_commit(lambda: _sender().put(sender.QueueChanged(cobot_id)))


def cell_stop_on_commit(stop: CellStop) -> None:
    """Shows the STOP as it is once the transaction commits (its users read along)."""
    stop = CellStop.objects.select_related("stopped_by", "resumed_by").get(pk=stop.pk)
    event: LiveEvent = {"type": "cell-stop", "stop": payloads.stop_data(stop)}
    organisation = stop.organisation_id
    send_event_on_commit(
        [organisation_group(organisation)], event, organisation=organisation, cell=stop.cell
    )


def membership_ended_on_commit(user_id: int, organisation_id: int) -> None:
    """Closes, after commit, the user's sockets on the organisation: at once, not on the
    consumers' next membership check."""
    ended = sender.MembershipEnded(user_group(user_id), organisation_id)
    transaction.on_commit(lambda: _sender().put(ended))


async def send_cobot_state(state: CobotStateData, *, organisation: int, cell: str) -> None:
    """Sends a cobot's gateway state now (the monitor's; no transaction is involved)."""
    event: LiveEvent = {"type": "cobot-state", "states": [state]}
    await sender.group_send_all([sender.Send(cell_groups(organisation, cell), organisation,
                                             [event], [cell])])  # fmt: skip


# The sender -----------------------------------------------------------------------------


def hold() -> Hold:
    """Keeps this process's deltas back until released, HOLD_LIMIT at most (hrc.live.sender)."""
    return _sender().hold()


def flush(timeout: float = FLUSH_TIMEOUT) -> bool:
    """Waits until everything queued so far has been sent; False when the sender did not finish."""
    return _sender().flush(timeout)


def serve_from(loop: asyncio.AbstractEventLoop) -> None:
    """Sends through `loop` from now on: the in-memory channel layer (the embedded demo)
    works only from the loop its consumers run on."""
    sender.server_loop = loop


def _sender() -> sender.Sender:
    return sender.current(_queue_sends)


def _queue_sends(cobot_ids: list[int]) -> list[sender.Send]:
    return [
        sender.Send([organisation_group(organisation)], organisation,
                    [{"type": "cobot-queue", "queue": data}], [cell])
        for organisation, cell, data in selectors.cobot_queues(cobot_ids)
    ]  # fmt: skip
