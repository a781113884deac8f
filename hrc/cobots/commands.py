"""The one rule for commanding a robot from a service: outside any transaction.

A robot is not rolled back with the rows: a command sent inside a transaction
that then rolls back has moved the robot all the same. And a lock held across
a network call stalls every writer that waits for the row (on the embedded
SQLite, every writer at all) for as long as the robot takes to answer. So a
service claims the right to send in a committed conditional update (so the
command is never sent twice), sends with `outside_transaction`, and records
what came of it in a short transaction of its own.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TypeVar

from django.db import connection

T = TypeVar("T")


class CommandInTransaction(RuntimeError):
    """A robot command was about to go out while a transaction was open: a bug of the caller."""


def outside_transaction(command: Callable[[], T]) -> T:
    """Runs `command` (a call to a robot) once it is sure no transaction is open.

    Raises CommandInTransaction, sending nothing, inside `transaction.atomic`.
    """
    if in_transaction():
        raise CommandInTransaction(
            "A robot command must go out after the rows are committed (hrc.cobots.commands)."
        )
    return command()


def in_transaction() -> bool:
    """Whether this thread's connection is inside `transaction.atomic`, not counting the block
    a test case wraps every test in (the same exception Django makes for durable blocks)."""
    return any(not getattr(block, "_from_testcase", False) for block in connection.atomic_blocks)
