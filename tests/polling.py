"""Waiting in tests for what other processes and threads do: a condition, polled until it holds."""

import time
from collections.abc import Callable
from typing import Any


def until(condition: Callable[[], Any], timeout: float = 30.0, interval: float = 0.02) -> Any:
    """The first truthy value of `condition()`, polled every `interval` s; fails after `timeout` s."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        value = condition()
        if value:
            return value
        time.sleep(interval)
    raise AssertionError("condition not reached in time")
