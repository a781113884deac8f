"""Certificates, trust lists and users for the cobot gateways and the driver.

Each gateway (an asyncua OPC UA server, one per cobot) serves only
Basic256Sha256 SignAndEncrypt and asks for a user name and password. The
driver (an asyncua client) talks only to gateways whose certificate it has
pinned; a gateway talks only to clients whose certificate is in its trust
list. Everything lives under one PKI directory, which the command
`python manage.py cobot_certificates` fills (settings.HRC_PKI_DIR, var/pki
by default):

    <pki>/gateways/<cobot>/cert.der       the gateway's certificate (URI urn:hrc:cobot:<cobot>)
    <pki>/gateways/<cobot>/key.pem        its private key (0600)
    <pki>/gateways/<cobot>/trusted/*.der  client certificates this gateway accepts
    <pki>/gateways/<cobot>/users.json     user name → salted PBKDF2-SHA256 hash (0600)
    <pki>/driver/cert.der                 the driver's client certificate (URI urn:hrc:driver)
    <pki>/driver/key.pem                  its private key (0600)
    <pki>/driver/trusted/<cobot>.der      the pinned certificate of each gateway

Trust is by exact certificate, not by issuer: there is no CA to run, and
revoking a client is deleting its file from `trusted/` (then restarting the
gateway, which reads the trust list and the users at start).

This module imports no Django models; it takes every path explicitly.
"""

from __future__ import annotations

import base64
import datetime
import hashlib
import hmac
import ipaddress
import json
import os
import re
import secrets
import tempfile
from collections.abc import Collection, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from asyncua import ua
from asyncua.client.client import Client
from asyncua.common.utils import ServiceError
from asyncua.crypto import cert_gen, uacrypto
from asyncua.crypto.permission_rules import User, UserRole
from asyncua.crypto.security_policies import SecurityPolicyBasic256Sha256
from asyncua.server.server import Server
from asyncua.server.user_managers import UserManager
from asyncua.ua.status_codes import StatusCodes
from cryptography import x509
from cryptography.hazmat.primitives.serialization import Encoding
from cryptography.x509.oid import ExtendedKeyUsageOID

if TYPE_CHECKING:
    from asyncua.server.internal_server import InternalServer

DRIVER_URI = "urn:hrc:driver"
GATEWAY_URI_PREFIX = "urn:hrc:cobot:"
# Renewing a certificate means re-pinning it on the other side, so certificates
# live long; revocation is by removing the file from a trust list instead.
DEFAULT_DAYS = 5 * 365
DEFAULT_GATEWAY_HOSTS = ("localhost", "127.0.0.1")
# OWASP's 2023 figure for PBKDF2-HMAC-SHA256. A login costs ~0.1 s of the
# gateway's event loop, and only a client with a trusted certificate gets that far.
PBKDF2_ITERATIONS = 600_000
MIN_PBKDF2_ITERATIONS = 200_000
USERS_FORMAT_VERSION = 1

# Cobot names become directory names and URNs: no separators, no "..".
_COBOT_NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9_-]{0,99}")
_USERNAME = re.compile(r"[^\s:]{1,64}")


class PkiError(Exception):
    """A certificate, key, trust list, users file or credential is missing or wrong.

    The message names the file or variable and how to fix it, never a secret.
    """


@dataclass(frozen=True)
class _PartyFiles:
    """A party's own certificate and key, and the certificates it trusts."""

    folder: Path

    @property
    def cert(self) -> Path:
        return self.folder / "cert.der"

    @property
    def key(self) -> Path:
        return self.folder / "key.pem"

    @property
    def trusted(self) -> Path:
        return self.folder / "trusted"


@dataclass(frozen=True)
class GatewayFiles(_PartyFiles):
    """Where one gateway's files live (see the module docstring)."""

    @property
    def users(self) -> Path:
        return self.folder / "users.json"


@dataclass(frozen=True)
class DriverFiles(_PartyFiles):
    """Where the driver's files live (see the module docstring)."""

    def pinned(self, cobot: str) -> Path:
        return self.trusted / f"{check_cobot_name(cobot)}.der"


def check_cobot_name(cobot: str) -> str:
    """Returns `cobot` when it is safe as a directory name and URN part; raises PkiError otherwise."""
    if not _COBOT_NAME.fullmatch(cobot):
        raise PkiError(
            f"{cobot!r} cannot name a gateway: use letters, digits, '-' and '_' "
            "(at most 100, starting with a letter or digit)."
        )
    return cobot


def gateway_files(pki_dir: Path, cobot: str) -> GatewayFiles:
    return GatewayFiles(Path(pki_dir) / "gateways" / check_cobot_name(cobot))


def driver_files(pki_dir: Path) -> DriverFiles:
    return DriverFiles(Path(pki_dir) / "driver")


def gateway_uri(cobot: str) -> str:
    """The gateway's application URI; its certificate carries the same URI or peers reject it."""
    return GATEWAY_URI_PREFIX + check_cobot_name(cobot)


# --- Files -----------------------------------------------------------------


def _write_atomically(path: Path, data: bytes, mode: int) -> None:
    """Writes `data` to `path` with `mode` from the first byte on, replacing it in one step.

    A crash leaves the old file or the new one, never half a key; and a key is
    never readable by others, not even between create and chmod.
    """
    path.parent.mkdir(parents=True, exist_ok=True, mode=0o700)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.")  # created 0600
    try:
        os.fchmod(fd, mode)
        with os.fdopen(fd, "wb") as file:
            file.write(data)
            file.flush()
            os.fsync(file.fileno())
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def _read(path: Path, what: str, cobot: str | None) -> bytes:
    try:
        return path.read_bytes()
    except FileNotFoundError:
        create = f"python manage.py cobot_certificates {cobot or '<cobot>'}"
        raise PkiError(f"{what} {path} is missing; create it with `{create}`.") from None
    except OSError as exc:
        raise PkiError(f"Cannot read {what} {path}: {exc.strerror}.") from None


def _der(certificate: x509.Certificate) -> bytes:
    return certificate.public_bytes(Encoding.DER)


def _load_der_certificate(path: Path, what: str, cobot: str | None) -> bytes:
    """The DER bytes of the certificate at `path`, checked to parse."""
    data = _read(path, what, cobot)
    try:
        x509.load_der_x509_certificate(data)
    except ValueError:
        raise PkiError(f"{what} {path} is not a DER certificate.") from None
    return data


# --- Certificates ----------------------------------------------------------


def _subject_alt_names(uri: str, hosts: Sequence[str]) -> list[x509.GeneralName]:
    names: list[x509.GeneralName] = [x509.UniformResourceIdentifier(uri)]
    for host in hosts:
        try:
            names.append(x509.IPAddress(ipaddress.ip_address(host)))
        except ValueError:
            names.append(x509.DNSName(host))
    return names


def _make_certificate(
    files: GatewayFiles | DriverFiles,
    uri: str,
    common_name: str,
    hosts: Sequence[str],
    days: int,
    force: bool,
) -> Path:
    if not force and (files.cert.exists() or files.key.exists()):
        raise PkiError(
            f"{files.cert} or {files.key} already exists; pass force=True (--force) to replace "
            "it, then re-run trust so the peers learn the new certificate."
        )
    key = cert_gen.generate_private_key()
    # asyncua's helper sets the key usages OPC UA asks of an application
    # instance certificate (digitalSignature, nonRepudiation, keyEncipherment,
    # dataEncipherment, keyCertSign for a self-signed one) and the SAN.
    certificate = cert_gen.generate_self_signed_app_certificate(
        key,
        common_name,
        {"organizationName": "hrc"},
        _subject_alt_names(uri, hosts),
        [ExtendedKeyUsageOID.SERVER_AUTH, ExtendedKeyUsageOID.CLIENT_AUTH],
        days=days,
    )
    # The key first: a crash in between then leaves a key nobody uses, never a
    # certificate that trust_each_other could pin while its key is missing.
    _write_atomically(files.key, cert_gen.dump_private_key_as_pem(key), 0o600)
    _write_atomically(files.cert, _der(certificate), 0o644)
    return files.cert


def make_gateway_certificate(
    pki_dir: Path,
    cobot: str,
    hosts: Sequence[str] = DEFAULT_GATEWAY_HOSTS,
    days: int = DEFAULT_DAYS,
    *,
    force: bool = False,
) -> Path:
    """Creates the gateway's RSA-2048 self-signed certificate and key; returns the certificate's path.

    `hosts` are the DNS names and IP addresses clients reach the gateway by.
    Raises PkiError when either file exists and `force` is false.
    """
    uri = gateway_uri(cobot)
    return _make_certificate(
        gateway_files(pki_dir, cobot), uri, f"hrc gateway {cobot}", hosts, days, force
    )


def make_driver_certificate(
    pki_dir: Path,
    hosts: Sequence[str] = ("localhost",),
    days: int = DEFAULT_DAYS,
    *,
    force: bool = False,
) -> Path:
    """Creates the driver's client certificate and key (one per installation); returns the certificate's path.

    Raises PkiError when either file exists and `force` is false.
    """
    return _make_certificate(driver_files(pki_dir), DRIVER_URI, "hrc driver", hosts, days, force)


def certificate_hosts(cert_path: Path) -> frozenset[str]:
    """The DNS names and IP addresses in the certificate's SAN (what `hosts` made it for)."""
    certificate = x509.load_der_x509_certificate(
        _load_der_certificate(cert_path, "The certificate", None)
    )
    try:
        san = certificate.extensions.get_extension_for_class(x509.SubjectAlternativeName).value
    except x509.ExtensionNotFound:
        return frozenset()
    addresses = (str(address) for address in san.get_values_for_type(x509.IPAddress))
    return frozenset([*san.get_values_for_type(x509.DNSName), *addresses])


def trust_each_other(pki_dir: Path, cobot: str) -> tuple[Path, Path]:
    """Puts the driver's certificate in the gateway's trust list and pins the gateway's in the driver's.

    Returns (the copy in the gateway's trust list, the driver's pin). Safe to
    run again: it overwrites both with the current certificates.
    """
    gateway, driver = gateway_files(pki_dir, cobot), driver_files(pki_dir)
    driver_cert = _load_der_certificate(driver.cert, "The driver certificate", cobot)
    gateway_cert = _load_der_certificate(gateway.cert, f"The certificate of gateway {cobot}", cobot)
    accepted, pinned = gateway.trusted / "driver.der", driver.pinned(cobot)
    _write_atomically(accepted, driver_cert, 0o644)
    _write_atomically(pinned, gateway_cert, 0o644)
    return accepted, pinned


def trusted_certificates(trusted_dir: Path) -> frozenset[bytes]:
    """The DER bytes of every `*.der` file in `trusted_dir`; an absent folder trusts nobody."""
    if not trusted_dir.is_dir():
        return frozenset()
    return frozenset(
        _load_der_certificate(path, "The trusted certificate", None)
        for path in sorted(trusted_dir.glob("*.der"))
    )


# --- Users -----------------------------------------------------------------


def _hash_password(password: str, salt: bytes, iterations: int) -> bytes:
    return hashlib.pbkdf2_hmac("sha256", password.encode(), salt, iterations)


def _b64(data: bytes) -> str:
    return base64.b64encode(data).decode("ascii")


def read_users(users_file: Path) -> dict[str, dict[str, Any]]:
    """The users file's entries by user name; raises PkiError when it is missing or malformed."""
    try:
        document = json.loads(users_file.read_text())
    except FileNotFoundError:
        raise PkiError(
            f"The users file {users_file} is missing; add a user with "
            "`python manage.py cobot_certificates <cobot> --user NAME --password-env VAR`."
        ) from None
    except (OSError, ValueError) as exc:
        raise PkiError(f"Cannot read the users file {users_file}: {exc}.") from None
    if not isinstance(document, dict) or document.get("version") != USERS_FORMAT_VERSION:
        raise PkiError(
            f"The users file {users_file} is not in format version {USERS_FORMAT_VERSION}."
        )
    users = document.get("users")
    if not isinstance(users, dict):
        raise PkiError(f"The users file {users_file} has no 'users' object.")
    return users


def check_username(username: str) -> str:
    """Returns `username` when a users file can hold it; raises PkiError otherwise."""
    if not _USERNAME.fullmatch(username):
        raise PkiError("A user name has 1 to 64 characters, none of them a space or ':'.")
    return username


def add_gateway_user(pki_dir: Path, cobot: str, username: str, password: str) -> Path:
    """Adds `username` to the gateway's users file, or gives it a new password; returns the file's path.

    Only a salted PBKDF2-SHA256 hash is stored. User names have no spaces or
    ':' (the credentials secret is `username:password`); passwords are not empty.
    """
    check_username(username)
    if not password:
        raise PkiError(f"The password for {username} is empty.")
    users_file = gateway_files(pki_dir, cobot).users
    users = read_users(users_file) if users_file.exists() else {}
    salt = secrets.token_bytes(16)
    users[username] = {
        "algorithm": "pbkdf2_sha256",
        "iterations": PBKDF2_ITERATIONS,
        "salt": _b64(salt),
        "hash": _b64(_hash_password(password, salt, PBKDF2_ITERATIONS)),
    }
    document = {"version": USERS_FORMAT_VERSION, "users": users}
    # 0600: hashes are not passwords, but an offline guesser should not get them either.
    _write_atomically(users_file, json.dumps(document, indent=2, sort_keys=True).encode(), 0o600)
    return users_file


class GatewayUserManager(UserManager):  # type: ignore[misc]  # asyncua is untyped here (pyproject)
    """An asyncua user manager: a user with the right password, on a channel from a trusted client.

    `trusted` is the set of client certificates (DER) whose secure channel may
    log in; None skips that check. asyncua hands `get_user` the certificate of
    the secure channel itself, which the client proved it holds the key of;
    checking it here closes two gaps asyncua leaves open: its certificate
    validator sees only the certificate a client *claims* in CreateSession
    (anyone can claim the driver's public certificate), and it lets a
    session be activated on an unsecured channel even when no None endpoint
    is published.
    """

    def __init__(self, users_file: Path, trusted: Collection[bytes] | None = None) -> None:
        # Read once: a gateway takes user changes at its next start, like trust list changes.
        self._users = read_users(Path(users_file))
        self._trusted = None if trusted is None else frozenset(trusted)

    def get_user(
        self,
        iserver: InternalServer,
        username: str | None = None,
        password: str | None = None,
        certificate: Any = None,
    ) -> User | None:
        """The user for a correct name and password; None otherwise, and for anonymous logins."""
        if self._trusted is not None and certificate not in self._trusted:
            return None
        if username is None or password is None:
            return None
        if self._password_matches(username, password):
            return User(role=UserRole.User, name=username)
        return None

    def _password_matches(self, username: str, password: str) -> bool:
        entry = self._users.get(username)
        if entry is None:
            # Hash anyway, so that the answer's timing says nothing about which names exist.
            _hash_password(password, b"\0" * 16, PBKDF2_ITERATIONS)
            return False
        try:
            salt, expected = base64.b64decode(entry["salt"]), base64.b64decode(entry["hash"])
            iterations = int(entry["iterations"])
        except (KeyError, TypeError, ValueError):
            return False
        if entry.get("algorithm") != "pbkdf2_sha256" or iterations < MIN_PBKDF2_ITERATIONS:
            return False
        return hmac.compare_digest(_hash_password(password, salt, iterations), expected)


# --- Wiring asyncua --------------------------------------------------------


class TrustListValidator:
    """An asyncua certificate validator: accepts exactly the certificates given, within their validity."""

    def __init__(self, trusted: Collection[bytes]) -> None:
        self._trusted = frozenset(trusted)

    async def __call__(self, certificate: x509.Certificate, app: ua.ApplicationDescription) -> None:
        if _der(certificate) not in self._trusted:
            raise ServiceError(StatusCodes.BadCertificateUntrusted)
        now = datetime.datetime.now(datetime.UTC)
        if not certificate.not_valid_before_utc <= now <= certificate.not_valid_after_utc:
            raise ServiceError(StatusCodes.BadCertificateTimeInvalid)


async def secure_server(server: Server, pki_dir: Path, cobot: str) -> None:
    """Makes `server` the gateway of `cobot`: Basic256Sha256 SignAndEncrypt, user names, trusted clients.

    Call after `await server.init()` (the application URI is written into the
    address space) and before `server.start()` (endpoints are built from
    these settings at start). Raises PkiError naming the missing file.
    """
    files = gateway_files(pki_dir, cobot)
    uri = gateway_uri(cobot)
    certificate = _load_der_certificate(files.cert, f"The certificate of gateway {cobot}", cobot)
    key = _read(files.key, f"The private key of gateway {cobot}", cobot)
    _check_uri(certificate, uri, files.cert)
    trusted = trusted_certificates(files.trusted)
    if not trusted:
        raise PkiError(
            f"Gateway {cobot} trusts no client: {files.trusted} has no .der certificate; "
            f"run `python manage.py cobot_certificates {cobot}`."
        )
    users = GatewayUserManager(files.users, trusted)
    await server.load_certificate(certificate)
    await server.load_private_key(key, format="pem")
    await server.set_application_uri(uri)
    server.set_security_policy([ua.SecurityPolicyType.Basic256Sha256_SignAndEncrypt])
    # What set_security_IDs(["Username"]) does, without its deprecation warning.
    server.set_identity_tokens([ua.UserNameIdentityToken])
    # get_user is looked up on the internal server at every ActivateSession,
    # so replacing the manager after construction is as good as Server(user_manager=...).
    server.iserver.set_user_manager(users)
    server.set_certificate_validator(TrustListValidator(trusted))


async def secure_client(
    client: Client, pki_dir: Path, cobot: str, username: str, password: str
) -> None:
    """Makes `client` the driver talking to `cobot`'s gateway: its certificate, the pinned one, a user.

    Call before `client.connect()`; reads files only, no network. `connect()`
    then fails unless the gateway holds the pinned certificate's key: asyncua
    encrypts the channel request to the pinned key, so an impostor cannot even
    answer (the client times out), and it rejects a session answer carrying
    another certificate. After such a timeout, `check_gateway_certificate`
    tells a re-keyed gateway from an unreachable one.
    """
    files = driver_files(pki_dir)
    certificate = _load_der_certificate(files.cert, "The driver certificate", cobot)
    key = _read(files.key, "The driver's private key", cobot)
    pinned = _pinned_certificate(files, cobot)
    client.application_uri = DRIVER_URI
    await client.set_security(
        SecurityPolicyBasic256Sha256,
        certificate,
        # Bytes without a file name: asyncua needs to be told they are PEM.
        uacrypto.CertProperties(key, extension="pem"),
        server_certificate=pinned,
        mode=ua.MessageSecurityMode.SignAndEncrypt,
    )
    # asyncua already compares the session answer's certificate with the pin;
    # this states the rule here rather than relying on that detail.
    client.certificate_validator = TrustListValidator({pinned})
    client.set_user(username)
    client.set_password(password)


async def check_gateway_certificate(
    url: str, pki_dir: Path, cobot: str, timeout: float = 4
) -> None:
    """Raises PkiError unless the gateway at `url` announces a secure endpoint with the pinned certificate.

    A diagnostic, not a protection (the announcement travels unsecured and an
    impostor could copy the genuine, public certificate): it turns the timeout
    a re-keyed or --insecure gateway causes into a message that says so.
    Network errors propagate as asyncua raises them.
    """
    pinned = _pinned_certificate(driver_files(pki_dir), cobot)
    # A fresh client: discovery runs over the unsecured channel every OPC UA server keeps open.
    endpoints = await Client(url, timeout=timeout).connect_and_get_server_endpoints()
    secure = [
        endpoint
        for endpoint in endpoints
        if endpoint.SecurityPolicyUri == SecurityPolicyBasic256Sha256.URI
        and endpoint.SecurityMode == ua.MessageSecurityMode.SignAndEncrypt
    ]
    if not secure:
        raise PkiError(
            f"Gateway {cobot} offers no Basic256Sha256 SignAndEncrypt endpoint; "
            "is it running with --insecure?"
        )
    # Exact bytes: our gateways send their certificate alone, never a chain.
    if any(endpoint.ServerCertificate != pinned for endpoint in secure):
        raise PkiError(
            f"Gateway {cobot} presented an unknown certificate. If it was given a new one, "
            f"pin it again with `python manage.py cobot_certificates {cobot}`."
        )


def _pinned_certificate(files: DriverFiles, cobot: str) -> bytes:
    path = files.pinned(cobot)
    pinned = _load_der_certificate(path, f"The pinned certificate of gateway {cobot}", cobot)
    _check_uri(pinned, gateway_uri(cobot), path)
    return pinned


def _check_uri(certificate: bytes, uri: str, path: Path) -> None:
    """Raises PkiError unless the certificate's SAN carries `uri` (peers compare it with the application URI)."""
    try:
        san = x509.load_der_x509_certificate(certificate).extensions.get_extension_for_class(
            x509.SubjectAlternativeName
        )
    except x509.ExtensionNotFound:
        raise PkiError(f"The certificate {path} has no subject alternative name.") from None
    if uri not in san.value.get_values_for_type(x509.UniformResourceIdentifier):
        raise PkiError(
            f"The certificate {path} is not for {uri}; it was made for another application."
        )


# --- The --insecure rule -----------------------------------


def is_loopback(host: str) -> bool:
    """True for 'localhost', 127.0.0.0/8 and ::1 (also bracketed or IPv4-mapped); --insecure needs one."""
    if host.lower() == "localhost":
        return True
    try:
        address = ipaddress.ip_address(host.removeprefix("[").removesuffix("]"))
    except ValueError:
        return False
    if isinstance(address, ipaddress.IPv6Address) and address.ipv4_mapped is not None:
        address = address.ipv4_mapped
    return address.is_loopback
