"""The tablets' socket over a real WebSocket: who gets in, the snapshot, deltas in order, the wall."""

from __future__ import annotations

import pytest
from django.contrib.auth.models import User
from websockets.exceptions import ConnectionClosed, InvalidStatus

from hrc.cases import services as case_services
from hrc.cases.models import Case, WorkItem
from hrc.live import groups
from hrc.live.consumers import RECHECK_SECONDS
from hrc.organisations import services as organisation_services
from hrc.organisations.models import Membership, Organisation
from tests.live.client import db, open_socket, receive, receive_until, run
from tests.live.server import LiveServer, session_cookie

pytestmark = pytest.mark.django_db(transaction=True)


def test_a_socket_without_a_session_is_refused(server: LiveServer) -> None:
    async def scenario() -> None:
        socket = await open_socket(server, None)
        refused = await receive(socket)
        assert refused["type"] == "refused"
        assert "Sign in" in refused["reason"]
        with pytest.raises(ConnectionClosed) as closed:
            await receive(socket)
        assert closed.value.rcvd is not None
        assert closed.value.rcvd.code == 4401

    run(scenario())


def test_a_page_of_another_site_cannot_open_the_socket(server: LiveServer, operator: User) -> None:
    cookie = session_cookie(operator)

    async def scenario() -> None:
        with pytest.raises(InvalidStatus) as refused:
            await open_socket(server, cookie, origin="http://evil.example")
        assert refused.value.response.status_code == 403

    run(scenario())


def test_an_outsider_naming_our_organisation_is_refused(
    server: LiveServer, organisation: Organisation, outsider: User
) -> None:
    cookie = session_cookie(outsider)

    async def scenario() -> None:
        socket = await open_socket(server, cookie, f"?organisation={organisation.pk}")
        refused = await receive(socket)
        assert refused == {
            "type": "refused",
            "reason": "You are not a member of this organisation.",
        }
        with pytest.raises(ConnectionClosed) as closed:
            await receive(socket)
        assert closed.value.rcvd is not None
        assert closed.value.rcvd.code == 4403

    run(scenario())


def test_a_bad_cell_name_is_refused_with_a_reason(server: LiveServer, operator: User) -> None:
    cookie = session_cookie(operator)

    async def scenario() -> None:
        socket = await open_socket(server, cookie, "?cell=a%20b")
        refused = await receive(socket)
        assert refused["type"] == "refused"
        assert "'a b' is not a cell name" in refused["reason"]

    run(scenario())


def test_a_cell_the_organisation_does_not_have_is_refused_with_a_reason(
    server: LiveServer, operator: User, organisation: Organisation, other_organisation: Organisation
) -> None:
    """Not a live tablet of nothing: a cell of another organisation is no cell here either."""
    organisation_services.ensure_cell(other_organisation, "cell1")
    cookie = session_cookie(operator)

    async def scenario() -> None:
        socket = await open_socket(server, cookie, "?cell=cell1")
        refused = await receive(socket)
        assert refused == {
            "type": "refused",
            "reason": "There is no cell 'cell1' in this organisation.",
        }
        with pytest.raises(ConnectionClosed) as closed:
            await receive(socket)
        assert closed.value.rcvd is not None
        assert closed.value.rcvd.code == 4404

    run(scenario())


def test_the_operator_gets_a_snapshot_then_numbered_deltas(
    server: LiveServer, operator: User, choice_case: Case
) -> None:
    cookie = session_cookie(operator)
    [count] = WorkItem.objects.filter(case=choice_case)

    async def scenario() -> None:
        await db(groups.flush)  # the case's start was broadcast before the tablet came
        socket = await open_socket(server, cookie)
        snapshot = await receive(socket)
        assert snapshot["type"] == "snapshot"
        assert snapshot["user"]["username"] == operator.username
        [case] = snapshot["cases"]
        assert case["id"] == choice_case.pk
        assert case["seq"] == choice_case.last_seq
        [item] = snapshot["work_items"]
        assert item["id"] == count.pk
        assert item["state"] == "offered"
        assert item["candidates"] == [operator.pk]

        await db(case_services.start_work_item, count, user=operator)
        await db(groups.flush)
        delta = await receive_until(socket, lambda e: e["type"] == "work-item")
        assert delta["case"] == choice_case.pk
        assert delta["seq"] == case["seq"] + 1
        assert delta["event"] == "task-started"
        assert delta["item"]["state"] == "running"
        assert delta["item"]["claimed_by"] == operator.pk
        await socket.close()

    run(scenario())


def test_an_outsider_connected_to_their_own_organisation_sees_nothing_of_ours(
    server: LiveServer, operator: User, outsider: User, choice_case: Case
) -> None:
    ours, theirs = session_cookie(operator), session_cookie(outsider)
    [count] = WorkItem.objects.filter(case=choice_case)

    async def scenario() -> None:
        outsider_socket = await open_socket(server, theirs)
        snapshot = await receive(outsider_socket)
        assert snapshot["type"] == "snapshot"
        assert snapshot["cases"] == []
        assert snapshot["work_items"] == []
        our_socket = await open_socket(server, ours)
        await receive(our_socket)

        await db(case_services.start_work_item, count, user=operator)
        await db(groups.flush)
        # Ours arrives; by then theirs would have too.
        await receive_until(our_socket, lambda e: e["type"] == "work-item")
        with pytest.raises(TimeoutError):
            await receive(outsider_socket, timeout=1.0)

    run(scenario())


def test_a_resync_request_gets_a_fresh_snapshot(
    server: LiveServer, operator: User, choice_case: Case
) -> None:
    cookie = session_cookie(operator)

    async def scenario() -> None:
        socket = await open_socket(server, cookie)
        first = await receive(socket)
        await db(case_services.start_case, choice_case.version, started_by=None,
                 actor_mapping={"o": {"users": [operator.pk]}})  # fmt: skip
        await socket.send('{"type": "resync"}')
        fresh = await receive_until(socket, lambda e: e["type"] == "snapshot")
        assert len(fresh["cases"]) == len(first["cases"]) + 1

    run(scenario())


def test_a_member_who_leaves_the_organisation_is_cut_off(
    server: LiveServer, operator: User, organisation: Organisation, choice_case: Case
) -> None:
    cookie = session_cookie(operator)

    async def scenario() -> None:
        socket = await open_socket(server, cookie)
        assert (await receive(socket))["type"] == "snapshot"
        await db(Membership.objects.filter(user=operator, organisation=organisation).delete)
        # Within one round of the server's membership check (every RECHECK_SECONDS).
        refused = await receive_until(
            socket, lambda e: e["type"] == "refused", timeout=RECHECK_SECONDS + 5
        )
        assert "no longer a member" in refused["reason"]
        with pytest.raises(ConnectionClosed):
            await receive(socket, timeout=5)

    run(scenario())


@pytest.mark.parametrize("ending", ["deactivated", "removed"])
def test_a_member_an_admin_lets_go_is_cut_off_at_once_not_at_the_next_check(
    server: LiveServer, operator: User, admin: User, organisation: Organisation, ending: str
) -> None:
    cookie = session_cookie(operator)
    membership = Membership.objects.get(user=operator, organisation=organisation)

    def let_go() -> None:
        if ending == "deactivated":
            organisation_services.deactivate_member(membership, by=admin)
        else:
            organisation_services.remove_member(membership)

    async def scenario() -> None:
        socket = await open_socket(server, cookie)
        assert (await receive(socket))["type"] == "snapshot"
        await db(let_go)
        # Well before the periodic check would have noticed.
        refused = await receive_until(
            socket, lambda e: e["type"] == "refused", timeout=RECHECK_SECONDS - 3
        )
        assert "no longer a member" in refused["reason"]
        with pytest.raises(ConnectionClosed):
            await receive(socket, timeout=5)

    run(scenario())


def test_a_cell_tablet_gets_the_case_deltas_too(
    server: LiveServer, operator: User, choice_case: Case, organisation: Organisation
) -> None:
    organisation_services.ensure_cell(organisation, "A")
    cookie = session_cookie(operator)
    [count] = WorkItem.objects.filter(case=choice_case)

    async def scenario() -> None:
        await db(groups.flush)
        socket = await open_socket(server, cookie, "?cell=A")
        snapshot = await receive(socket)
        assert snapshot["cell"] == "A"
        await db(case_services.claim_work_item, count, user=operator)
        await db(groups.flush)
        delta = await receive_until(socket, lambda e: e["type"] == "work-item")
        assert delta["event"] == "task-claimed"

    run(scenario())
