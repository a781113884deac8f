"""The one rule for robot commands: never inside a transaction."""

import pytest
from django.db import transaction

from hrc.cobots.commands import CommandInTransaction, in_transaction, outside_transaction

pytestmark = pytest.mark.django_db


def test_a_command_goes_out_when_no_transaction_is_open() -> None:
    sent: list[str] = []

    assert outside_transaction(lambda: sent.append("PauseProgram")) is None
    assert sent == ["PauseProgram"]
    assert not in_transaction()  # the block a test runs in does not count


def test_a_command_inside_a_transaction_is_refused_and_not_sent() -> None:
    sent: list[str] = []

    with transaction.atomic(), pytest.raises(CommandInTransaction):
        outside_transaction(lambda: sent.append("PauseProgram"))

    assert sent == []
