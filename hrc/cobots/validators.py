"""Checks for a cobot's endpoint and credentials reference, shared by the model, admin and API.

These check one value; what needs the database or the network (an endpoint
registered once, a secret of the cobot's organisation, HRC_COBOT_NETWORKS)
is Cobot.clean's.
"""

import re
from urllib.parse import urlsplit

from django.core.exceptions import ValidationError

from hrc.cobots.choices import CredentialsKind
from hrc_gateway.endpoints import EndpointError, endpoint_key

ENDPOINT_SCHEME = "opc.tcp"
SECRET_NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.-]{0,63}")
# Sources that read the worker's own environment or files: every organisation's cobots
# would share them, so one organisation could borrow another's credentials.
WORKER_SOURCES = ("env:", "file:")
WORKER_SOURCES_REFUSED = (
    "Credentials are not read from the worker's environment or files ('env:' and 'file:' "
    "sources): an admin of the organisation creates a named credentials secret (Cobots → "
    "Credentials, or `manage.py cobot_secret`), and the cobot uses 'secret:NAME'."
)


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
    try:
        endpoint_key(value)
    except EndpointError as error:
        raise ValidationError(str(error)) from None


def split_credentials_source(value: str) -> tuple[CredentialsKind, str] | None:
    """(kind, secret name) of `none` or `secret:NAME`; None for anything else.

    The one reading of a source, for the model's check and the driver's lookup alike.
    """
    kind, _, reference = value.partition(":")
    if kind == CredentialsKind.NONE and not reference:
        return CredentialsKind.NONE, ""
    if kind == CredentialsKind.SECRET and SECRET_NAME.fullmatch(reference):
        return CredentialsKind.SECRET, reference
    return None


def credentials_source_problem(value: str) -> str | None:
    """Why the source is refused, or None. Never quotes it: a secret typed here must not echo."""
    if split_credentials_source(value) is not None:
        return None
    if value.startswith(WORKER_SOURCES):
        return WORKER_SOURCES_REFUSED
    return (
        "The credentials source must be 'none' or 'secret:NAME', NAME a credentials secret of "
        "the organisation; it says where the secret is, never the secret itself."
    )


def validate_credentials_source(value: str) -> None:
    """Accepts `none` or `secret:NAME`: a reference, never a secret."""
    problem = credentials_source_problem(value)
    if problem is not None:
        raise ValidationError(problem)


def validate_secret_name(value: str) -> None:
    if not SECRET_NAME.fullmatch(value):
        raise ValidationError(
            f"{value!r} is not a secret name: up to 64 letters, digits, '.', '_' or '-', "
            "starting with a letter or digit."
        )
