"""Tests: the real PostgreSQL and Redis of the machine unless the environment points elsewhere."""

import hashlib
import os
from typing import Any

os.environ.setdefault("DATABASE_URL", "postgres://postgres@127.0.0.1:5432/test")
os.environ.setdefault("REDIS_URL", "redis://127.0.0.1:6379/0")

from hrc.settings.base import *  # noqa: F403
from hrc.settings.base import BASE_DIR, CHANNEL_LAYERS, DATABASES

# One test database per checkout, so that two clones testing at once on the
# same server (a developer's tree and a fresh CI clone) never drop each
# other's database; pytest-xdist adds its worker suffix to this name.
# HRC_TEST_RUN separates two runs in one checkout.
_run = hashlib.sha1(str(BASE_DIR).encode()).hexdigest()[:8] + os.environ.get("HRC_TEST_RUN", "")
DATABASES["default"]["TEST"] = {"NAME": f"test_hrc_{_run}"}
# Groups are named after row ids, which repeat across test databases: each
# run and xdist worker gets its own channel-layer namespace on the shared Redis.
_layer: dict[str, Any] = CHANNEL_LAYERS["default"]
if "CONFIG" in _layer:
    _layer["CONFIG"]["prefix"] = f"test_hrc_{_run}_{os.environ.get('PYTEST_XDIST_WORKER', 'main')}"

PASSWORD_HASHERS = ["django.contrib.auth.hashers.MD5PasswordHasher"]  # speed; never in prod
