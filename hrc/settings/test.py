"""Tests: the real PostgreSQL and Redis of the machine unless the environment points elsewhere."""

import hashlib
import os

os.environ.setdefault("DATABASE_URL", "postgres://postgres@127.0.0.1:5432/test")
os.environ.setdefault("REDIS_URL", "redis://127.0.0.1:6379/0")

from hrc.settings.base import *  # noqa: F403
from hrc.settings.base import BASE_DIR, DATABASES

# One test database per checkout, so that two clones testing at once on the
# same server (a developer's tree and a fresh CI clone) never drop each
# other's database; pytest-xdist adds its worker suffix to this name.
_checkout = hashlib.sha1(str(BASE_DIR).encode()).hexdigest()[:8]
DATABASES["default"]["TEST"] = {"NAME": f"test_hrc_{_checkout}"}

PASSWORD_HASHERS = ["django.contrib.auth.hashers.MD5PasswordHasher"]  # speed; never in prod
