"""A cobot's credentials: the named secret of its own organisation, encrypted at rest.

The driver and the monitor ask `credentials_for`; nothing else
decrypts a secret, and nothing shows one back. The key is Fernet's
(AES-128-CBC with HMAC-SHA256), from HRC_SECRETS_KEY or, when that is unset,
derived from SECRET_KEY: every installation then encrypts without another
setting, and one that sets HRC_SECRETS_KEY can rotate SECRET_KEY (sessions,
signed links) without losing its cobots' credentials.
"""

from __future__ import annotations

import base64
import json

from cryptography.fernet import Fernet, InvalidToken
from cryptography.hazmat.primitives import hashes
from cryptography.hazmat.primitives.kdf.hkdf import HKDF
from django.conf import settings

from hrc.cobots.choices import CredentialsKind
from hrc.cobots.models import CredentialsSecret
from hrc.cobots.validators import credentials_source_problem, split_credentials_source

# Domain separation: the same SECRET_KEY yields another key for anything else it derives.
_KEY_INFO = b"hrc cobot credentials secrets v1"


class CredentialsError(Exception):
    """The cobot's credentials cannot be had; the message names the secret, never its value."""


def seal(username: str, password: str) -> str:
    """The user name and password as stored: a Fernet token (ASCII)."""
    plain = json.dumps({"username": username, "password": password}).encode()
    return _fernet().encrypt(plain).decode("ascii")


def unseal(sealed: str) -> tuple[str, str]:
    """(username, password) of a stored token; raises CredentialsError when the key changed."""
    try:
        values = json.loads(_fernet().decrypt(sealed.encode("ascii")))
    except (InvalidToken, ValueError):
        raise CredentialsError(
            "it cannot be decrypted with this installation's key (was HRC_SECRETS_KEY or "
            "SECRET_KEY changed?); an admin sets it again"
        ) from None
    return str(values["username"]), str(values["password"])


def credentials_for(cobot: str, organisation_id: int, source: str) -> tuple[str, str] | None:
    """The (username, password) the cobot signs in with; None when its source is 'none'.

    Reads only a secret of the cobot's own organisation. Raises CredentialsError
    for an env:/file: source of an older installation, or a missing secret.
    """
    parts = split_credentials_source(source)
    if parts is None:
        raise CredentialsError(f"{cobot}: {credentials_source_problem(source)}")
    kind, name = parts
    if kind == CredentialsKind.NONE:
        return None
    secret = CredentialsSecret.objects.filter(organisation_id=organisation_id, name=name).first()
    if secret is None:
        raise CredentialsError(f"{cobot}: its organisation has no credentials secret named {name}.")
    try:
        return unseal(secret.sealed)
    except CredentialsError as error:
        raise CredentialsError(f"{cobot}: the credentials secret {name}: {error}.") from None


def _fernet() -> Fernet:
    source = settings.HRC_SECRETS_KEY or settings.SECRET_KEY
    key = HKDF(algorithm=hashes.SHA256(), length=32, salt=None, info=_KEY_INFO).derive(
        source.encode()
    )
    return Fernet(base64.urlsafe_b64encode(key))
