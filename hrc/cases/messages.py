"""Messages to cases: correlation by name and keys, an early-arrival buffer with a time to live.

A message transition (a silent transition with a `message` configuration)
waits in a case until a message of its name arrives whose correlation keys
equal the case's values for them. A message that finds no waiting case is
kept until it expires; a case that starts waiting takes the oldest matching
one. The sender's message id makes a repeated send harmless.

A case sends messages too (a `send` key): progress.send_message writes the row
in the transaction that fires the sending transition, and deliver_sent_message
offers it to the other cases after commit, through the same _deliver as one
from outside, so no case is locked while the sender's lock is held.
"""

from __future__ import annotations

import datetime as dt
from collections.abc import Mapping
from typing import Any

from django.contrib.auth.models import User
from django.db import IntegrityError, transaction
from django.utils import timezone

from hrc.cases import dispatch, progress
from hrc.cases.choices import CaseStatus
from hrc.cases.dispatch import Task
from hrc.cases.models import Case, Message
from hrc.cases.nets import case_net, net_of
from hrc.errors import Conflict, Invalid
from hrc.organisations.models import Organisation
from hrc.patterns.models import PatternVersion

DEFAULT_TTL_SECONDS = progress.MESSAGE_TTL_SECONDS
MAX_TTL_SECONDS = 7 * 24 * 3600


def receive_message(
    organisation: Organisation,
    *,
    message_id: str,
    name: str,
    correlation: Mapping[str, Any] | None = None,
    payload: Mapping[str, Any] | None = None,
    ttl_seconds: int = DEFAULT_TTL_SECONDS,
    sent_by: User | None = None,
) -> tuple[Message, bool]:
    """Delivers a message to the case waiting for it, or buffers it. Returns (message, created).

    A message id seen before returns the first message unchanged (created False).
    """
    if not message_id or not name:
        raise Invalid("A message needs a 'message_id' and a 'name'.")
    if not 1 <= ttl_seconds <= MAX_TTL_SECONDS:
        raise Invalid(f"'ttl_seconds' must be 1–{MAX_TTL_SECONDS}.")
    existing = Message.objects.filter(organisation=organisation, message_id=message_id).first()
    if existing is not None:
        return _same_message(existing, name, correlation, payload), False
    try:
        with transaction.atomic():
            message = Message.objects.create(
                organisation=organisation, message_id=message_id, name=name,
                correlation=dict(correlation or {}), payload=dict(payload or {}),
                expires_at=timezone.now() + dt.timedelta(seconds=ttl_seconds), sent_by=sent_by,
            )  # fmt: skip
    except IntegrityError:  # the same id, sent twice at once: the other send won
        first = Message.objects.get(organisation=organisation, message_id=message_id)
        return _same_message(first, name, correlation, payload), False
    _deliver(message)
    message.refresh_from_db()
    return message, True


def _same_message(
    first: Message,
    name: str,
    correlation: Mapping[str, Any] | None,
    payload: Mapping[str, Any] | None,
) -> Message:
    """The first message with this id, when this send repeats it; Conflict when it says something else."""
    if (first.name, first.correlation, first.payload) != (
        name,
        dict(correlation or {}),
        dict(payload or {}),
    ):
        raise Conflict(
            f"Message id {first.message_id!r} was used before for a different message "
            f"({first.name!r}); a repeated send must be identical, a new message needs a new id."
        )
    return first


def _deliver(message: Message) -> None:
    """Offers the message to each running case of the organisation waiting for its name."""
    running = Case.objects.filter(
        organisation_id=message.organisation_id, status=CaseStatus.RUNNING
    )
    versions = PatternVersion.objects.filter(cases__in=running).distinct()
    listening = [
        v.pk for v in versions if any(m.name == message.name for m in case_net(v).messages.values())
    ]
    candidates = (
        running.filter(version_id__in=listening)
        .order_by("started_at", "id")
        .values_list("pk", flat=True)
    )
    for case_id in candidates:
        with transaction.atomic():
            case = progress.lock_case(case_id)
            if case.status != CaseStatus.RUNNING:
                continue
            if progress.take_message(case, net_of(case), message.pk):
                case.save()
                return


def deliver_sent_message(message_pk: int) -> None:
    """Offers a message a case sent to the cases waiting for it; nothing when one took it
    already (its own case, or this task run before), or it expired. A case that comes to
    wait for it later takes it itself (progress.advance)."""
    message = Message.objects.filter(
        pk=message_pk, consumed_at__isnull=True, expires_at__gt=timezone.now()
    ).first()
    if message is not None:
        _deliver(message)
    Message.objects.filter(pk=message_pk, offered_at__isnull=True).update(offered_at=timezone.now())


def sweep_sent_messages(grace_seconds: float = 2.0) -> int:
    """Rings again for the messages cases sent that were never offered: their doorbell was
    lost (the broker restarted), and a case already waiting would wait for ever. Returns how
    many."""
    now = timezone.now()
    lost = list(
        Message.objects.filter(
            sent_from_case__isnull=False, offered_at__isnull=True, consumed_at__isnull=True,
            expires_at__gt=now, received_at__lt=now - dt.timedelta(seconds=grace_seconds),
        ).values_list("pk", flat=True)[:100]
    )  # fmt: skip
    with transaction.atomic():  # send_on_commit needs a transaction to wait for
        for message_pk in lost:
            dispatch.send_on_commit(Task.DELIVER_MESSAGE, message_pk)
    return len(lost)


def purge_expired_messages() -> int:
    """Deletes buffered messages past their time to live that no case took; returns how many."""
    deleted, _ = Message.objects.filter(
        consumed_at__isnull=True, expires_at__lte=timezone.now()
    ).delete()
    return deleted
