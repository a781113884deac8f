"""Signing in: how guessing passwords is slowed down, on every path that takes one.

The login page, the admin's login and `POST /api/token/` all call Django's
`authenticate()`, so django-axes, which sits in front of it as an
authentication backend, covers all three with one rule and one record (in the
database, so every web process agrees, and visible in the admin). DRF's
throttles would cover only the API and count in a cache per process unless
Redis is configured. The rule: past HRC_LOGIN_FAILURE_LIMIT wrong passwords
from one client address, that address is locked out (429) for a cool-off that
doubles with every further HRC_LOGIN_FAILURE_LIMIT failures from it in the
past day, from one minute up to an hour.
"""

from __future__ import annotations

from datetime import timedelta
from typing import Any

from axes.backends import AxesStandaloneBackend
from axes.models import AccessFailureLog
from django.conf import settings
from django.contrib.auth.base_user import AbstractBaseUser
from django.http import HttpRequest
from django.utils import timezone

FIRST_COOL_OFF = timedelta(minutes=1)
LONGEST_COOL_OFF = timedelta(hours=1)
# Failures this far back make the next lockout longer.
MEMORY = timedelta(days=1)
MOST_DOUBLINGS = 6  # 64 minutes: past the longest already


def cool_off(request: HttpRequest | None = None) -> timedelta:
    """How long the request's address stays locked out (AXES_COOLOFF_TIME): one minute,
    doubled for every further HRC_LOGIN_FAILURE_LIMIT failures from it in the past day.

    Attempts made while locked out count too: hammering a locked door makes it
    stay locked longer.
    """
    address = getattr(request, "axes_ip_address", None)
    if not address:
        return FIRST_COOL_OFF
    failures: int = AccessFailureLog.objects.filter(
        ip_address=address, attempt_time__gte=timezone.now() - MEMORY
    ).count()
    limit: int = settings.AXES_FAILURE_LIMIT
    doublings = min(max(failures // limit - 1, 0), MOST_DOUBLINGS)
    return min(FIRST_COOL_OFF * (1 << doublings), LONGEST_COOL_OFF)


class LockoutBackend(AxesStandaloneBackend):  # type: ignore[misc]  # axes is untyped
    """Axes' check, for sign-ins that come from a client address.

    Without a request (a management command, a test client's login, a service
    checking a password) there is no address to lock out, so nothing to check:
    axes would refuse such a call outright.
    """

    def authenticate(
        self, request: HttpRequest | None, username: str | None = None,
        password: str | None = None, **kwargs: Any,
    ) -> AbstractBaseUser | None:  # fmt: skip
        if request is None:
            return None
        return super().authenticate(request, username, password, **kwargs)  # type: ignore[no-any-return]
