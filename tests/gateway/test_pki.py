"""The cobots' PKI: certificates, trust, users, credentials, and real asyncua peers on 127.0.0.1.

Certificates and the gateways are made once per module (a key takes tens of
milliseconds, an asyncua server a second to start and one to stop); tests
that change files work on a copy.
"""

from __future__ import annotations

import json
import os
import shutil
import stat
import subprocess
import sys
from collections.abc import AsyncIterator, Awaitable, Callable
from contextlib import asynccontextmanager
from io import StringIO
from pathlib import Path
from typing import TYPE_CHECKING, Any, cast

import pytest
import pytest_asyncio
from asyncua import ua
from asyncua.client.client import Client
from asyncua.crypto.permission_rules import UserRole
from asyncua.crypto.security_policies import SecurityPolicyBasic256Sha256
from asyncua.server.server import Server
from asyncua.ua import uaerrors
from cryptography import x509
from cryptography.hazmat.primitives.asymmetric import rsa
from cryptography.x509.oid import ExtendedKeyUsageOID
from django.core.management import call_command
from django.core.management.base import CommandError

from hrc.cobots.simulated import free_port
from hrc_gateway import pki
from hrc_gateway.pki import PkiError

if TYPE_CHECKING:
    from asyncua.server.internal_server import InternalServer

COBOT = "cobot1"
USER, PASSWORD = "driver", "correct horse battery staple"
BASE_DIR = Path(__file__).resolve().parents[2]

# GatewayUserManager ignores the server asyncua passes in.
NO_SERVER = cast("InternalServer", None)

# The async tests share the module's event loop, so they can share its gateways.
module_loop = pytest.mark.asyncio(loop_scope="module")


@pytest.fixture(scope="module")
def pki_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The installation's PKI: the driver, gateway cobot1, mutual trust, one user."""
    folder = tmp_path_factory.mktemp("pki")
    pki.make_driver_certificate(folder)
    pki.make_gateway_certificate(folder, COBOT)
    pki.trust_each_other(folder, COBOT)
    pki.add_gateway_user(folder, COBOT, USER, PASSWORD)
    return folder


@pytest.fixture(scope="module")
def stranger_dir(tmp_path_factory: pytest.TempPathFactory, pki_dir: Path) -> Path:
    """Another installation: its own driver and its own cobot1, trusting our driver.

    Its driver pins our gateway (it knows the public certificate), and its
    gateway trusts our driver and has our user: only the keys differ.
    """
    folder = tmp_path_factory.mktemp("stranger")
    pki.make_driver_certificate(folder)
    pki.make_gateway_certificate(folder, COBOT)
    pki.add_gateway_user(folder, COBOT, USER, PASSWORD)
    ours, theirs = pki.driver_files(pki_dir), pki.driver_files(folder)
    theirs.trusted.mkdir()
    shutil.copy(ours.pinned(COBOT), theirs.pinned(COBOT))
    trusted = pki.gateway_files(folder, COBOT).trusted
    trusted.mkdir()
    shutil.copy(ours.cert, trusted / "driver.der")
    return folder


@asynccontextmanager
async def _gateway(
    pki_dir: Path | None, cobot: str = COBOT, *, insecure: bool = False
) -> AsyncIterator[str]:
    """A running asyncua server secured by `secure_server` (or not at all); yields its URL."""
    server = Server()
    await server.init()
    url = f"opc.tcp://127.0.0.1:{free_port()}/"
    server.set_endpoint(url)
    if insecure:
        server.set_security_policy([ua.SecurityPolicyType.NoSecurity])
    else:
        assert pki_dir is not None
        await pki.secure_server(server, pki_dir, cobot)
    await server.start()
    try:
        yield url
    finally:
        await server.stop()


@pytest_asyncio.fixture(scope="module", loop_scope="module")
async def gateway_url(pki_dir: Path) -> AsyncIterator[str]:
    async with _gateway(pki_dir) as url:
        yield url


@pytest_asyncio.fixture(scope="module", loop_scope="module")
async def impostor_url(stranger_dir: Path) -> AsyncIterator[str]:
    """A gateway that calls itself cobot1 but holds another key."""
    async with _gateway(stranger_dir) as url:
        yield url


async def _driver(
    url: str, pki_dir: Path, username: str = USER, password: str = PASSWORD, timeout: float = 4
) -> Client:
    client = Client(url, timeout=timeout)
    await pki.secure_client(client, pki_dir, COBOT, username, password)
    return client


async def _read_server_state(client: Client) -> Any:
    async with client:
        return await client.nodes.server_state.read_value()


# --- Over the wire -----------------------------------------------------------


@module_loop
async def test_the_driver_with_the_right_password_reads_from_the_gateway(
    gateway_url: str, pki_dir: Path
) -> None:
    client = await _driver(gateway_url, pki_dir)
    assert await _read_server_state(client) == ua.ServerState.Running


@module_loop
async def test_the_gateway_publishes_only_basic256sha256_signandencrypt_with_user_names(
    gateway_url: str,
) -> None:
    endpoints = await Client(gateway_url, timeout=4).connect_and_get_server_endpoints()
    assert [(e.SecurityPolicyUri, e.SecurityMode) for e in endpoints] == [
        (SecurityPolicyBasic256Sha256.URI, ua.MessageSecurityMode.SignAndEncrypt)
    ]
    assert [t.TokenType for t in endpoints[0].UserIdentityTokens] == [ua.UserTokenType.UserName]
    assert endpoints[0].Server.ApplicationUri == "urn:hrc:cobot:cobot1"


@module_loop
@pytest.mark.parametrize(
    ("username", "password"),
    [(USER, "wrong password"), ("nobody", PASSWORD)],
    ids=["wrong-password", "unknown-user"],
)
async def test_a_wrong_user_or_password_is_refused(
    gateway_url: str, pki_dir: Path, username: str, password: str
) -> None:
    client = await _driver(gateway_url, pki_dir, username, password)
    with pytest.raises(uaerrors.BadUserAccessDenied):
        await _read_server_state(client)


@module_loop
async def test_an_anonymous_client_on_a_secure_channel_is_refused(
    gateway_url: str, pki_dir: Path
) -> None:
    driver = pki.driver_files(pki_dir)
    client = Client(gateway_url, timeout=4)
    client.application_uri = pki.DRIVER_URI
    await client.set_security(
        SecurityPolicyBasic256Sha256,
        str(driver.cert),
        str(driver.key),
        server_certificate=str(driver.pinned(COBOT)),
    )
    with pytest.raises(uaerrors.BadIdentityTokenRejected):
        await _read_server_state(client)


@module_loop
async def test_a_client_without_security_finds_no_endpoint(gateway_url: str) -> None:
    client = Client(gateway_url, timeout=4)
    client.set_user(USER)
    client.set_password(PASSWORD)
    with pytest.raises(uaerrors.UaError, match="No matching endpoints"):
        await _read_server_state(client)


@module_loop
async def test_a_client_ignoring_the_endpoints_cannot_log_in_over_an_unsecured_channel(
    gateway_url: str,
) -> None:
    # asyncua itself would activate this session (its None discovery channel
    # stays open for sessions too); the gateway's user manager refuses it.
    async def log_in(client: Client) -> None:
        await _create_session_raw(client, gateway_url)
        await client.uaclient.activate_session(_password_login(USER, PASSWORD))

    with pytest.raises(uaerrors.BadUserAccessDenied):
        await _over_raw_channel(Client(gateway_url, timeout=4), log_in)


@module_loop
async def test_a_session_is_useless_before_it_is_activated(gateway_url: str) -> None:
    async def read_unauthenticated(client: Client) -> None:
        await _create_session_raw(client, gateway_url)
        await client.nodes.server_state.read_value()

    with pytest.raises(uaerrors.BadSessionNotActivated):
        await _over_raw_channel(Client(gateway_url, timeout=4), read_unauthenticated)


@module_loop
async def test_a_client_certificate_not_in_the_trust_list_is_refused(
    gateway_url: str, stranger_dir: Path
) -> None:
    client = await _driver(gateway_url, stranger_dir)
    with pytest.raises(uaerrors.BadCertificateUntrusted):
        await _read_server_state(client)


@module_loop
async def test_claiming_the_drivers_public_certificate_does_not_get_a_stranger_in(
    gateway_url: str, pki_dir: Path, stranger_dir: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # The stranger's channel runs on its own key but its CreateSession names
    # our driver's certificate, which asyncua's validator alone would accept.
    client = await _driver(gateway_url, stranger_dir)
    real_driver = pki.driver_files(pki_dir).cert.read_bytes()
    create_session = client.uaclient.create_session

    async def claim(params: ua.CreateSessionParameters) -> ua.CreateSessionResult:
        params.ClientCertificate = real_driver
        return await create_session(params)

    monkeypatch.setattr(client.uaclient, "create_session", claim)
    with pytest.raises(uaerrors.BadUserAccessDenied):
        await _read_server_state(client)


@module_loop
async def test_a_gateway_with_an_unpinned_certificate_is_refused(
    impostor_url: str, pki_dir: Path
) -> None:
    # asyncua encrypts the channel request to the pinned key: the impostor
    # cannot read it and never answers.
    client = await _driver(impostor_url, pki_dir, timeout=1)
    with pytest.raises(TimeoutError):
        await _read_server_state(client)


@module_loop
async def test_check_gateway_certificate_names_an_unpinned_gateway(
    impostor_url: str, gateway_url: str, pki_dir: Path
) -> None:
    await pki.check_gateway_certificate(gateway_url, pki_dir, COBOT)
    with pytest.raises(PkiError, match="Gateway cobot1 presented an unknown certificate"):
        await pki.check_gateway_certificate(impostor_url, pki_dir, COBOT)


@module_loop
async def test_check_gateway_certificate_names_an_insecure_gateway(pki_dir: Path) -> None:
    async with _gateway(None, insecure=True) as url:
        with pytest.raises(PkiError, match="no Basic256Sha256 SignAndEncrypt endpoint"):
            await pki.check_gateway_certificate(url, pki_dir, COBOT)


async def _over_raw_channel(client: Client, steps: Callable[[Client], Awaitable[None]]) -> None:
    """Runs `steps` on an unsecured channel opened by hand, as a client of another make might."""
    await client.connect_socket()
    try:
        await client.send_hello()
        await client.open_secure_channel()
        await steps(client)
    finally:
        client.disconnect_socket()


async def _create_session_raw(client: Client, url: str) -> None:
    """CreateSession without asyncua's client-side check that the endpoint exists."""
    params = ua.CreateSessionParameters()
    params.ClientDescription = ua.ApplicationDescription(ApplicationUri="urn:someone")
    params.EndpointUrl = url
    params.SessionName = "raw"
    params.RequestedSessionTimeout = 10_000
    params.ClientNonce = os.urandom(32)
    await client.uaclient.create_session(params)


def _password_login(username: str, password: str) -> ua.ActivateSessionParameters:
    token = ua.UserNameIdentityToken(PolicyId="username", UserName=username)
    token.Password = password.encode()
    return ua.ActivateSessionParameters(UserIdentityToken=token)


# --- Missing pieces ------------------------------------------------------------


@module_loop
async def test_secure_server_names_a_missing_certificate_and_the_command(tmp_path: Path) -> None:
    with pytest.raises(PkiError) as raised:
        await pki.secure_server(Server(), tmp_path, COBOT)
    message = str(raised.value)
    assert str(tmp_path / "gateways" / COBOT / "cert.der") in message
    assert "python manage.py cobot_certificates cobot1" in message


@module_loop
async def test_secure_server_refuses_a_gateway_that_trusts_nobody(
    tmp_path: Path, pki_dir: Path
) -> None:
    shutil.copytree(pki_dir, tmp_path, dirs_exist_ok=True)
    shutil.rmtree(pki.gateway_files(tmp_path, COBOT).trusted)
    with pytest.raises(PkiError, match="trusts no client"):
        await pki.secure_server(Server(), tmp_path, COBOT)


@module_loop
async def test_secure_server_names_a_missing_users_file(tmp_path: Path, pki_dir: Path) -> None:
    shutil.copytree(pki_dir, tmp_path, dirs_exist_ok=True)
    pki.gateway_files(tmp_path, COBOT).users.unlink()
    with pytest.raises(PkiError, match=r"users file .*users\.json is missing"):
        await pki.secure_server(Server(), tmp_path, COBOT)


@module_loop
async def test_secure_client_names_a_missing_pin(tmp_path: Path, pki_dir: Path) -> None:
    shutil.copytree(pki_dir, tmp_path, dirs_exist_ok=True)
    with pytest.raises(PkiError, match=r"pinned certificate of gateway cobot2 .*cobot2\.der"):
        await pki.secure_client(Client("opc.tcp://127.0.0.1:4840"), tmp_path, "cobot2", "u", "p")


# --- Certificates and files ----------------------------------------------------


def test_the_gateway_certificate_is_made_for_opc_ua(pki_dir: Path) -> None:
    certificate = x509.load_der_x509_certificate(
        pki.gateway_files(pki_dir, COBOT).cert.read_bytes()
    )
    san = certificate.extensions.get_extension_for_class(x509.SubjectAlternativeName).value
    usage = certificate.extensions.get_extension_for_class(x509.KeyUsage).value
    extended = certificate.extensions.get_extension_for_class(x509.ExtendedKeyUsage).value
    public_key = certificate.public_key()
    assert isinstance(public_key, rsa.RSAPublicKey)
    assert public_key.key_size == 2048
    assert certificate.issuer == certificate.subject
    assert san.get_values_for_type(x509.UniformResourceIdentifier) == ["urn:hrc:cobot:cobot1"]
    assert pki.certificate_hosts(pki.gateway_files(pki_dir, COBOT).cert) == {
        "localhost",
        "127.0.0.1",
    }
    assert usage.digital_signature
    assert usage.key_encipherment
    assert usage.data_encipherment
    assert usage.content_commitment  # nonRepudiation
    assert set(extended) == {ExtendedKeyUsageOID.SERVER_AUTH, ExtendedKeyUsageOID.CLIENT_AUTH}


def test_the_driver_certificate_carries_the_driver_uri(pki_dir: Path) -> None:
    certificate = x509.load_der_x509_certificate(pki.driver_files(pki_dir).cert.read_bytes())
    san = certificate.extensions.get_extension_for_class(x509.SubjectAlternativeName).value
    assert san.get_values_for_type(x509.UniformResourceIdentifier) == ["urn:hrc:driver"]


def test_keys_and_users_are_readable_by_the_owner_only(pki_dir: Path) -> None:
    gateway, driver = pki.gateway_files(pki_dir, COBOT), pki.driver_files(pki_dir)
    for secret in (gateway.key, driver.key, gateway.users):
        assert stat.S_IMODE(secret.stat().st_mode) == 0o600, secret


def test_trust_lists_hold_the_peers_certificates(pki_dir: Path) -> None:
    gateway, driver = pki.gateway_files(pki_dir, COBOT), pki.driver_files(pki_dir)
    assert (gateway.trusted / "driver.der").read_bytes() == driver.cert.read_bytes()
    assert driver.pinned(COBOT).read_bytes() == gateway.cert.read_bytes()


def test_certificates_are_not_overwritten_without_force(tmp_path: Path) -> None:
    first = pki.make_gateway_certificate(tmp_path, COBOT).read_bytes()
    with pytest.raises(PkiError, match="already exists"):
        pki.make_gateway_certificate(tmp_path, COBOT)
    assert pki.gateway_files(tmp_path, COBOT).cert.read_bytes() == first
    assert pki.make_gateway_certificate(tmp_path, COBOT, force=True).read_bytes() != first


@pytest.mark.parametrize("name", ["", "../etc", "a/b", ".hidden", "cobot 1", "x" * 101])
def test_a_cobot_name_that_is_not_a_plain_word_is_refused(tmp_path: Path, name: str) -> None:
    with pytest.raises(PkiError, match="cannot name a gateway"):
        pki.make_gateway_certificate(tmp_path, name)
    assert not any(tmp_path.iterdir())


# --- Users ---------------------------------------------------------------------


def test_the_users_file_holds_salted_hashes_not_passwords(tmp_path: Path) -> None:
    pki.add_gateway_user(tmp_path, COBOT, "alice", PASSWORD)
    users_file = pki.add_gateway_user(tmp_path, COBOT, "bob", PASSWORD)
    text = users_file.read_text()
    users = json.loads(text)["users"]
    assert PASSWORD not in text
    assert users["alice"]["salt"] != users["bob"]["salt"]
    assert users["alice"]["hash"] != users["bob"]["hash"]
    assert users["alice"]["iterations"] >= 200_000


def test_the_user_manager_knows_the_right_password_only(pki_dir: Path) -> None:
    manager = pki.GatewayUserManager(pki.gateway_files(pki_dir, COBOT).users)
    user = manager.get_user(NO_SERVER, USER, PASSWORD)
    assert user is not None
    assert (user.role, user.name) == (UserRole.User, USER)
    assert manager.get_user(NO_SERVER, USER, PASSWORD + "!") is None
    assert manager.get_user(NO_SERVER, "nobody", PASSWORD) is None
    assert manager.get_user(NO_SERVER) is None  # anonymous


def test_the_user_manager_wants_a_trusted_channel_certificate(pki_dir: Path) -> None:
    driver_cert = pki.driver_files(pki_dir).cert.read_bytes()
    manager = pki.GatewayUserManager(pki.gateway_files(pki_dir, COBOT).users, {driver_cert})
    assert manager.get_user(NO_SERVER, USER, PASSWORD, driver_cert) is not None
    assert manager.get_user(NO_SERVER, USER, PASSWORD, b"another") is None
    assert manager.get_user(NO_SERVER, USER, PASSWORD, None) is None


def test_a_new_password_replaces_the_old(tmp_path: Path) -> None:
    pki.add_gateway_user(tmp_path, COBOT, USER, "old")
    users_file = pki.add_gateway_user(tmp_path, COBOT, USER, "new")
    manager = pki.GatewayUserManager(users_file)
    assert manager.get_user(NO_SERVER, USER, "new") is not None
    assert manager.get_user(NO_SERVER, USER, "old") is None


@pytest.mark.parametrize("username", ["", "with space", "with:colon", "x" * 65])
def test_a_user_name_the_secret_format_cannot_carry_is_refused(
    tmp_path: Path, username: str
) -> None:
    with pytest.raises(PkiError, match="user name"):
        pki.add_gateway_user(tmp_path, COBOT, username, PASSWORD)


# --- The --insecure rule ------------------------------------------------------------


@pytest.mark.parametrize(
    ("host", "loopback"),
    [
        ("localhost", True),
        ("LOCALHOST", True),
        ("127.0.0.1", True),
        ("127.8.9.10", True),
        ("::1", True),
        ("[::1]", True),
        ("::ffff:127.0.0.1", True),
        ("0.0.0.0", False),
        ("::", False),
        ("192.168.1.20", False),
        ("128.0.0.1", False),
        ("localhost.example.com", False),
        ("cobot1.plant.local", False),
        ("", False),
    ],
)
def test_is_loopback(host: str, loopback: bool) -> None:
    assert pki.is_loopback(host) is loopback


# --- The command ---------------------------------------------------------------


def _run_command(*args: str) -> str:
    out = StringIO()
    call_command("cobot_certificates", *args, stdout=out)
    return out.getvalue()


def test_the_command_creates_the_layout(tmp_path: Path) -> None:
    output = _run_command("cobot1", "cobot2", "--pki", str(tmp_path))
    driver = pki.driver_files(tmp_path)
    for cobot in ("cobot1", "cobot2"):
        gateway = pki.gateway_files(tmp_path, cobot)
        assert stat.S_IMODE(gateway.key.stat().st_mode) == 0o600
        assert (gateway.trusted / "driver.der").read_bytes() == driver.cert.read_bytes()
        assert driver.pinned(cobot).read_bytes() == gateway.cert.read_bytes()
        assert f"{cobot}: created {gateway.cert}" in output
        assert f"{cobot}: no users yet" in output
    assert stat.S_IMODE(driver.key.stat().st_mode) == 0o600
    assert f"driver: created {driver.cert}" in output


def test_the_command_run_again_keeps_everything(tmp_path: Path) -> None:
    _run_command("cobot1", "--pki", str(tmp_path))
    before = {path: path.read_bytes() for path in tmp_path.rglob("*") if path.is_file()}
    output = _run_command("cobot1", "--pki", str(tmp_path))
    after = {path: path.read_bytes() for path in tmp_path.rglob("*") if path.is_file()}
    assert after == before
    assert "keeping" in output
    assert "created" not in output


def test_the_command_replaces_a_certificate_for_other_hosts_only_with_force(
    tmp_path: Path,
) -> None:
    _run_command("cobot1", "--pki", str(tmp_path))
    gateway = pki.gateway_files(tmp_path, COBOT)
    old = gateway.cert.read_bytes()
    with pytest.raises(CommandError, match=r"exists for other hosts .*--force"):
        _run_command("cobot1", "--pki", str(tmp_path), "--host", "cobot1.plant.local")
    assert gateway.cert.read_bytes() == old
    _run_command("cobot1", "--pki", str(tmp_path), "--host", "cobot1.plant.local", "--force")
    assert pki.certificate_hosts(gateway.cert) == {"cobot1.plant.local"}
    assert pki.driver_files(tmp_path).pinned(COBOT).read_bytes() == gateway.cert.read_bytes()


def test_the_command_reads_the_password_from_the_environment(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("HRC_TEST_GATEWAY_PASSWORD", "hunter2")
    output = _run_command(
        "cobot1",
        "--pki",
        str(tmp_path),
        "--user",
        USER,
        "--password-env",
        "HRC_TEST_GATEWAY_PASSWORD",
    )
    users_file = pki.gateway_files(tmp_path, COBOT).users
    manager = pki.GatewayUserManager(users_file)
    assert manager.get_user(NO_SERVER, USER, "hunter2") is not None
    assert f"{COBOT}: user {USER} saved in {users_file}" in output
    assert "hunter2" not in output + users_file.read_text()


def test_the_command_names_an_unset_password_variable_before_writing(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.delenv("HRC_TEST_GATEWAY_PASSWORD", raising=False)
    with pytest.raises(CommandError, match="HRC_TEST_GATEWAY_PASSWORD is not set"):
        _run_command(
            "cobot1",
            "--pki",
            str(tmp_path),
            "--user",
            USER,
            "--password-env",
            "HRC_TEST_GATEWAY_PASSWORD",
        )
    assert not any(tmp_path.iterdir())


def test_the_command_wants_user_and_password_variable_together(tmp_path: Path) -> None:
    with pytest.raises(CommandError, match="--user and --password-env go together"):
        _run_command("cobot1", "--pki", str(tmp_path), "--user", USER)


def test_the_command_fails_with_a_message_not_a_traceback(tmp_path: Path) -> None:
    result = subprocess.run(
        [sys.executable, "manage.py", "cobot_certificates", "../etc", "--pki", str(tmp_path)],
        cwd=BASE_DIR,
        capture_output=True,
        text=True,
        check=False,
        env={**os.environ, "DJANGO_SETTINGS_MODULE": "hrc.settings.test"},
    )
    assert result.returncode == 1
    assert "CommandError: '../etc' cannot name a gateway" in result.stderr
    assert "Traceback" not in result.stderr
