"""Messages a case sends (the `send` key): to another case through a real worker, to another
process of the same case at once, never twice, buffered like one from outside."""

from __future__ import annotations

import datetime as dt
from collections.abc import Callable
from typing import Any

import pytest
from django.contrib.auth.models import User
from django.db import transaction
from django.test import Client
from django.utils import timezone

from hrc.cases import services
from hrc.cases.choices import CaseStatus, EventType
from hrc.cases.dispatch import Task, registered
from hrc.cases.messages import deliver_sent_message, purge_expired_messages, receive_message
from hrc.cases.models import Case, Message, WorkItem
from hrc.celery import app
from hrc.errors import Invalid
from hrc.organisations.choices import Role
from hrc.organisations.models import Organisation
from hrc.patterns.models import PatternVersion
from tests import factories
from tests.support.polling import until
from tests.support.workers import WorkerProcess

PART_READY = {
    "name": "part-ready",
    "correlation": {"order": "=data.order"},
    "payload": {"part": "=data.part", "from": "=case.reference"},
}


def _sender_document(send: dict[str, Any] = PART_READY) -> dict[str, Any]:
    """One operator task, `prepare`, that sends `send` when it completes."""
    return {
        "format": "hrc-pattern/1",
        "name": "Sender",
        "actors": [{"id": "o", "type": "operator"}],
        "processes": [
            {
                "id": "N", "workpiece": "w", "actors": ["o"],
                "places": [{"id": "p1", "tokens": 1}, {"id": "p2"}],
                "transitions": [{"id": "prepare", "performer": "o", "send": send}],
                "arcs": [["p1", "prepare"], ["prepare", "p2"]],
            }
        ],
        "constraints": [],
    }  # fmt: skip


def _two_processes_document() -> dict[str, Any]:
    """Process A prepares and tells process B of the same case, which waits, then assembles."""
    return {
        "format": "hrc-pattern/1",
        "name": "Two processes",
        "actors": [{"id": "o", "type": "operator"}, {"id": "o2", "type": "operator"}],
        "processes": [
            {
                "id": "A", "workpiece": "w", "actors": ["o"],
                "places": [{"id": "a1", "tokens": 1}, {"id": "a2"}],
                "transitions": [{
                    "id": "prepare", "performer": "o",
                    "send": {"name": "go", "correlation": {"case": "=case.id"},
                             "payload": {"prepared_by": "A"}},
                }],
                "arcs": [["a1", "prepare"], ["prepare", "a2"]],
            },
            {
                "id": "B", "workpiece": "w", "actors": ["o2"],
                "places": [{"id": "b1", "tokens": 1}, {"id": "b2"}, {"id": "b3"}],
                "transitions": [
                    {"id": "wait_go", "message": {"name": "go", "correlation": {"case": "case.id"}}},
                    {"id": "assemble", "performer": "o2"},
                ],
                "arcs": [["b1", "wait_go"], ["wait_go", "b2"], ["b2", "assemble"],
                         ["assemble", "b3"]],
            },
        ],
        "constraints": [],
    }  # fmt: skip


@pytest.fixture
def publish(organisation: Organisation, engineer: User) -> Callable[..., PatternVersion]:
    def make(draft: dict[str, Any], where: Organisation = organisation) -> PatternVersion:
        by = engineer if where == organisation else factories.make_member(where, Role.ENGINEER)
        return factories.make_version(where, published_by=by, draft=draft)

    return make


def _start(
    version: PatternVersion, operator: User, operators: tuple[str, ...] = ("o",), **data: Any
) -> Case:
    actors = {actor: {"users": [operator.pk]} for actor in operators}
    assert version.published_by is not None
    return factories.make_case(
        version, started_by=version.published_by, actor_mapping=actors, data=data
    )


def _do(case: Case, task: str, operator: User) -> None:
    item = factories.open_work_item(case, task)
    services.start_work_item(item, user=operator)
    services.complete_work_item(item, user=operator)


def _waiting_receiver(version: PatternVersion, operator: User, order: str) -> Case:
    case = _start(version, operator, order=order)
    _do(case, "prepare", operator)
    return case


def _offered(case: Case) -> list[str]:
    return sorted(case.work_items.filter(state="offered").values_list("task", flat=True))


@pytest.mark.django_db(transaction=True)
def test_a_completed_task_sends_a_message_a_worker_delivers_to_the_case_waiting_for_it(
    publish: Callable[..., PatternVersion],
    operator: User,
    start_worker: Callable[..., WorkerProcess],
) -> None:
    start_worker()
    receivers = publish(factories.message_document())
    other = _waiting_receiver(receivers, operator, "A-2")
    receiver = _waiting_receiver(receivers, operator, "A-1")
    sender = _start(publish(_sender_document()), operator, order="A-1", part={"id": 7})

    _do(sender, "prepare", operator)

    until(lambda: _offered(receiver) == ["assemble"], timeout=30, message="not delivered")
    receiver.refresh_from_db()
    sender.refresh_from_db()
    assert receiver.data == {"order": "A-1", "part": {"id": 7}, "from": sender.reference}
    assert _offered(other) == []  # its order is another
    message = Message.objects.get()
    sent = sender.events.get(type=EventType.MESSAGE_SENT)
    assert message.message_id == f"case:{sender.pk}:prepare:{sent.seq}"
    assert (message.sent_by, message.sent_from_case, message.sent_from_transition) == (
        None, sender, "prepare",
    )  # fmt: skip
    assert (message.case, message.transition) == (receiver, "arrive")
    assert sent.task == "prepare"
    assert sent.detail == {
        "message": message.message_id, "name": "part-ready", "correlation": {"order": "A-1"},
    }  # fmt: skip
    received = receiver.events.get(type=EventType.MESSAGE_RECEIVED)
    assert received.detail == {"message": message.message_id, "name": "part-ready"}
    # The sent event follows the completion that sent it, in the same transaction.
    completed = sender.events.get(type=EventType.TASK_COMPLETED)
    assert sent.seq == completed.seq + 1
    assert sender.status == CaseStatus.COMPLETED


@pytest.mark.django_db(transaction=True)
def test_a_message_to_another_process_of_the_same_case_is_taken_in_the_same_transaction(
    publish: Callable[..., PatternVersion], operator: User
) -> None:
    version = publish(_two_processes_document())
    first, second = (_start(version, operator, ("o", "o2")) for _ in range(2))

    _do(first, "prepare", operator)

    # No worker runs here: the case's own loop took it before the completion committed.
    assert _offered(first) == ["assemble"]
    assert _offered(second) == ["prepare"]
    message = Message.objects.get()
    assert (message.sent_from_case, message.case, message.transition) == (first, first, "wait_go")
    assert message.correlation == {"case": first.pk}
    first.refresh_from_db()
    assert first.data == {"prepared_by": "A"}
    kinds = list(first.events.order_by("seq").values_list("type", flat=True))
    assert kinds.index(EventType.MESSAGE_SENT) < kinds.index(EventType.MESSAGE_RECEIVED)
    deliver_sent_message(message.pk)  # the delivery task after commit finds nothing to do
    assert _offered(second) == ["prepare"]
    _do(first, "assemble", operator)
    first.refresh_from_db()
    assert first.status == CaseStatus.COMPLETED


@pytest.mark.django_db(transaction=True)
def test_a_completion_rolled_back_and_done_again_sends_one_message(
    publish: Callable[..., PatternVersion], operator: User, monkeypatch: pytest.MonkeyPatch
) -> None:
    sender = _start(publish(_sender_document()), operator, order="B-1", part=1)
    item = factories.open_work_item(sender, "prepare")
    services.start_work_item(item, user=operator)
    sent_tasks: list[Any] = []
    monkeypatch.setattr(app, "send_task", lambda name, *args, **kwargs: sent_tasks.append(name))

    with pytest.raises(RuntimeError, match="dropped"):
        _complete_and_roll_back(item, operator)
    assert not Message.objects.exists()
    assert sent_tasks == []  # nothing is delivered of a firing that never was
    services.complete_work_item(item, user=operator)

    message = Message.objects.get()
    sent = sender.events.get(type=EventType.MESSAGE_SENT)
    assert message.message_id == f"case:{sender.pk}:prepare:{sent.seq}"
    assert sent_tasks == [Task.DELIVER_MESSAGE.value]


def _complete_and_roll_back(item: WorkItem, operator: User) -> None:
    with transaction.atomic():
        services.complete_work_item(item, user=operator)
        assert Message.objects.count() == 1
        raise RuntimeError("the connection dropped before the commit")


@pytest.mark.django_db(transaction=True)
def test_the_delivery_task_run_twice_delivers_once(
    publish: Callable[..., PatternVersion],
    operator: User,
    start_worker: Callable[..., WorkerProcess],
) -> None:
    receivers = publish(factories.message_document())
    first = _waiting_receiver(receivers, operator, "C-1")
    second = _waiting_receiver(receivers, operator, "C-1")
    sender = _start(publish(_sender_document()), operator, order="C-1", part=2)
    _do(sender, "prepare", operator)  # no worker yet: its delivery waits in the broker
    message = Message.objects.get()
    app.send_task(Task.DELIVER_MESSAGE.value, (message.pk,), ignore_result=True)  # once more

    start_worker()
    start_worker()
    until(lambda: Message.objects.filter(consumed_at__isnull=False).exists(), timeout=30)
    registered(Task.DELIVER_MESSAGE).run(message.pk)  # and a third time, here

    assert sorted([_offered(first), _offered(second)]) == [[], ["assemble"]]
    message.refresh_from_db()
    assert message.case in (first, second)
    assert Case.objects.filter(events__type=EventType.MESSAGE_RECEIVED).count() == 1


@pytest.mark.django_db(transaction=True)
def test_a_sent_message_nobody_waits_for_is_buffered_until_its_time_to_live_ends(
    publish: Callable[..., PatternVersion], operator: User
) -> None:
    sender = _start(publish(_sender_document()), operator, order="D-1", part=3)
    _do(sender, "prepare", operator)
    message = Message.objects.get()
    deliver_sent_message(message.pk)

    message.refresh_from_db()
    assert (message.case, message.consumed_at) == (None, None)
    lifetime = message.expires_at - message.received_at
    assert dt.timedelta(minutes=59) < lifetime <= dt.timedelta(hours=1)
    # A case that comes to wait for it later takes it, as an early message from outside.
    receiver = _waiting_receiver(publish(factories.message_document()), operator, "D-1")
    assert _offered(receiver) == ["assemble"]
    message.refresh_from_db()
    assert message.case == receiver
    # One that nobody took goes when its time is up.
    _do(sender_again := _start(sender.version, operator, order="D-2", part=4), "prepare", operator)
    late = Message.objects.get(sent_from_case=sender_again)
    Message.objects.filter(pk=late.pk).update(expires_at=timezone.now() - dt.timedelta(seconds=1))
    deliver_sent_message(late.pk)
    assert purge_expired_messages() == 1
    assert list(Message.objects.all()) == [message]


@pytest.mark.django_db(transaction=True)
def test_a_message_never_crosses_into_another_organisation(
    publish: Callable[..., PatternVersion],
    operator: User,
    other_organisation: Organisation,
) -> None:
    theirs = publish(factories.message_document(), other_organisation)
    outsider = factories.make_member(other_organisation, Role.OPERATOR)
    outside = _waiting_receiver(theirs, outsider, "E-1")
    sender = _start(publish(_sender_document()), operator, order="E-1", part=5)
    _do(sender, "prepare", operator)

    deliver_sent_message(Message.objects.get().pk)

    assert _offered(outside) == []
    assert Message.objects.get().consumed_at is None


@pytest.mark.django_db(transaction=True)
def test_a_send_that_fails_on_the_case_data_refuses_the_completion_naming_it(
    publish: Callable[..., PatternVersion], operator: User
) -> None:
    send = {"name": "part-ready", "payload": {"part": "=data.part.id"}}
    sender = _start(publish(_sender_document(send)), operator, part="no id")
    item = factories.open_work_item(sender, "prepare")
    services.start_work_item(item, user=operator)

    with pytest.raises(Invalid, match="The message 'part-ready' that prepare sends failed"):
        services.complete_work_item(item, user=operator)
    assert not Message.objects.exists()


@pytest.mark.django_db(transaction=True)
def test_the_case_page_shows_what_a_case_sent_and_who_took_it(
    publish: Callable[..., PatternVersion], operator: User, engineer: User, outsider: User
) -> None:
    receiver = _waiting_receiver(publish(factories.message_document()), operator, "F-1")
    sender = _start(publish(_sender_document()), operator, order="F-1", part=6)
    _do(sender, "prepare", operator)
    message = Message.objects.get()
    supervisor = Client()
    supervisor.force_login(engineer)

    waiting = _messages_section(supervisor, sender)
    assert "part-ready" in waiting
    assert message.message_id in waiting
    assert "waiting" in waiting
    deliver_sent_message(message.pk)
    sent = _messages_section(supervisor, sender)
    assert f"arrive of case {receiver.pk}" in sent
    taken = _messages_section(supervisor, receiver)
    assert f"prepare of case {sender.pk}" in taken
    assert "{&quot;order&quot;: &quot;F-1&quot;}" in taken
    stranger = Client()
    stranger.force_login(outsider)
    assert stranger.get(f"/cases/{sender.pk}/").status_code == 404


def _messages_section(client: Client, case: Case) -> str:
    response = client.get(f"/cases/{case.pk}/")
    assert response.status_code == 200
    page = response.content.decode()
    return page[page.index('id="messages"') : page.index('id="timeline"')]


@pytest.mark.django_db(transaction=True)
def test_a_lost_delivery_doorbell_is_rung_again_by_the_sweeper(
    publish: Callable[..., PatternVersion],
    operator: User,
    start_worker: Callable[..., WorkerProcess],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    receiver = _waiting_receiver(publish(factories.message_document()), operator, "G-1")
    sender = _start(publish(_sender_document()), operator, order="G-1", part=8)
    with monkeypatch.context() as broker_down:
        broker_down.setattr(app, "send_task", lambda *args, **kwargs: None)
        _do(sender, "prepare", operator)
    message = Message.objects.get()
    assert (message.offered_at, message.consumed_at) == (None, None)

    start_worker(beat=True)  # the beat's sweeper finds it

    until(lambda: _offered(receiver) == ["assemble"], timeout=30, message="never delivered")
    message.refresh_from_db()
    assert message.case == receiver
    # Marked offered once the delivery is over, so no sweep rings for it again.
    until(lambda: Message.objects.filter(offered_at__isnull=False).exists(), timeout=10)


@pytest.mark.django_db(transaction=True)
def test_a_message_transition_whose_send_fails_fails_its_case_with_an_incident(
    publish: Callable[..., PatternVersion], operator: User, organisation: Organisation
) -> None:
    document = factories.message_document()
    [arrive] = [t for t in document["processes"][0]["transitions"] if t["id"] == "arrive"]
    arrive["send"] = {"name": "passed-on", "payload": {"part": "=data.part.id"}}
    receiver = _waiting_receiver(publish(document), operator, "H-1")

    receive_message(
        organisation, message_id="m-h1", name="part-ready", correlation={"order": "H-1"},
        payload={"part": "no id"},
    )  # fmt: skip

    receiver.refresh_from_db()
    assert receiver.status == CaseStatus.FAILED
    [incident] = receiver.incidents.all()
    assert "The message 'passed-on' that arrive sends failed" in incident.message
    assert Message.objects.filter(name="passed-on").count() == 0
