"""API keys: `Authorization: Token <key>`, checked against hrc.organisations.models.ApiToken.

DRF's own token model keeps the key in clear, one per user for ever; here a
key is stored as its digest, expires, and is revoked with the password.
"""

from __future__ import annotations

from django.contrib.auth.models import User
from rest_framework.authentication import TokenAuthentication
from rest_framework.exceptions import AuthenticationFailed

from hrc.organisations import selectors, services
from hrc.organisations.models import ApiToken


class ApiTokenAuthentication(TokenAuthentication):
    """DRF's header parsing (and its 401 with `WWW-Authenticate: Token`), our keys."""

    def authenticate_credentials(self, key: str) -> tuple[User, ApiToken]:
        token = selectors.api_token_of(services.digest_of(key))
        if token is None:
            raise AuthenticationFailed(
                "Invalid or expired token; ask POST /api/token/ for a new one."
            )
        if not token.user.is_active:
            raise AuthenticationFailed("This user may no longer sign in.")
        return token.user, token
