"""The latest state each cobot's gateway reported, for snapshots: in Redis beside the channel layer.

The monitor (hrc.live.monitor) writes it as it broadcasts; a tablet that
connects reads it with its snapshot. Entries expire, so a monitor that
stopped leaves "unknown", not a state from long ago. Without Redis (the
embedded demo) it lives in this process only.
"""

from __future__ import annotations

import functools
import json
from typing import Any

import redis
from django.conf import settings

from hrc.live.events import CobotStateData

# A state older than this is not shown: the monitor re-reports at least every few seconds.
TTL_SECONDS = 15

_local: dict[int, CobotStateData] = {}


@functools.cache
def _client() -> redis.Redis | None:
    url = getattr(settings, "REDIS_URL", None)
    return redis.Redis.from_url(url) if url else None


def _key(cobot_id: int) -> str:
    config: Any = settings.CHANNEL_LAYERS["default"].get("CONFIG", {})
    return f"{config.get('prefix', 'asgi')}:hrc-cobot-state:{cobot_id}"


def remember(state: CobotStateData) -> None:
    client = _client()
    if client is None:
        _local[state["cobot"]] = state
        return
    client.set(_key(state["cobot"]), json.dumps(state), ex=TTL_SECONDS)


def recall(cobot_ids: list[int]) -> dict[int, CobotStateData]:
    """The remembered states of the cobots that have one."""
    client = _client()
    if client is None:
        return {i: _local[i] for i in cobot_ids if i in _local}
    if not cobot_ids:
        return {}
    values = client.mget([_key(i) for i in cobot_ids])
    return {i: json.loads(v) for i, v in zip(cobot_ids, values, strict=True) if v is not None}
