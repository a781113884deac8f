"""The STOP record in the admin: listed, never changed there."""

import pytest
from django.contrib.auth.models import User
from django.test import Client

from hrc.cobots.models import CellStop
from hrc.organisations.models import Organisation

pytestmark = pytest.mark.django_db


def test_stops_are_listed_and_read_only(
    staff_client: Client, organisation: Organisation, operator: User
) -> None:
    stop = CellStop.objects.create(organisation=organisation, cell="A", stopped_by=operator)

    listing = staff_client.get("/admin/cobots/cellstop/")
    change = staff_client.post(f"/admin/cobots/cellstop/{stop.pk}/change/", {"cell": "B"})

    assert listing.status_code == 200
    assert operator.username in listing.content.decode()
    assert change.status_code == 403
    stop.refresh_from_db()
    assert stop.cell == "A"
