"""Checks for a cobot's endpoint and credentials reference, shared by the model, admin and API."""

import re
from urllib.parse import urlsplit

from django.core.exceptions import ValidationError

from hrc.cobots.choices import CredentialsKind

ENDPOINT_SCHEME = "opc.tcp"
_ENV_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")


def validate_endpoint(value: str) -> None:
    """Accepts `opc.tcp://host[:port][/path]`; host names without a dot (Docker services) are fine."""
    try:
        parts = urlsplit(value)
        port = parts.port  # raises ValueError for a port that is not a number in range
    except ValueError as exc:
        raise ValidationError(f"{value!r} is not a valid URL: {exc}.") from None
    if parts.scheme != ENDPOINT_SCHEME:
        raise ValidationError(
            f"The endpoint must be an OPC UA URL starting with {ENDPOINT_SCHEME}://, got {value!r}."
        )
    if not parts.hostname:
        raise ValidationError(f"The endpoint {value!r} names no host.")
    if port == 0:
        raise ValidationError(f"The endpoint {value!r} has port 0.")
    if parts.username or parts.password:
        raise ValidationError(
            "Put no user name or password in the endpoint; use the credentials source instead."
        )


def split_credentials_source(value: str) -> tuple[CredentialsKind, str] | None:
    """(kind, reference) of `none`, `env:VARIABLE` or `file:/absolute/path`; None for anything else.

    The one reading of a source, for the model's check and the driver's lookup alike.
    """
    kind, _, reference = value.partition(":")
    if kind == CredentialsKind.NONE and not reference:
        return CredentialsKind.NONE, ""
    if kind == CredentialsKind.ENV and _ENV_NAME.fullmatch(reference):
        return CredentialsKind.ENV, reference
    if kind == CredentialsKind.FILE and reference.startswith("/"):
        return CredentialsKind.FILE, reference
    return None


def validate_credentials_source(value: str) -> None:
    """Accepts `none`, `env:VARIABLE` or `file:/absolute/path`: a reference, never a secret."""
    if split_credentials_source(value) is not None:
        return
    raise ValidationError(
        "The credentials source must be 'none', 'env:VARIABLE_NAME' or 'file:/absolute/path'; "
        "it says where the secret is, never the secret itself."
    )
