"""Waiting in tests and the bench for what other processes, threads and tasks do: a condition,
polled until it holds. One sync and one async variant, the same contract."""

from __future__ import annotations

import asyncio
import inspect
import time
from collections.abc import Awaitable, Callable
from typing import Any

Message = str | Callable[[], str]


def until(
    condition: Callable[[], Any],
    timeout: float = 30.0,
    interval: float = 0.02,
    message: Message = "condition not reached in time",
) -> Any:
    """The first truthy value of `condition()`, polled every `interval` s.

    Fails with AssertionError(`message`) after `timeout` s; a callable message is
    called then, so it can say what the state was.
    """
    deadline = time.monotonic() + timeout
    while True:
        value = condition()
        if value:
            return value
        if time.monotonic() >= deadline:
            raise AssertionError(_text(message))
        time.sleep(interval)


async def until_async(
    condition: Callable[[], Any | Awaitable[Any]],
    timeout: float = 5.0,
    interval: float = 0.005,
    message: Message = "condition not reached in time",
) -> Any:
    """`until` for a test's event loop: sleeps with asyncio, and awaits `condition()` when it
    is a coroutine function (a read over OPC UA)."""
    deadline = time.monotonic() + timeout
    while True:
        value = condition()
        if inspect.isawaitable(value):
            value = await value
        if value:
            return value
        if time.monotonic() >= deadline:
            raise AssertionError(_text(message))
        await asyncio.sleep(interval)


def _text(message: Message) -> str:
    return message if isinstance(message, str) else message()
