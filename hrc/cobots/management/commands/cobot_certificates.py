"""`python manage.py cobot_certificates cobot1 [cobot2 ...] [--pki DIR] [--host H ...]
[--user NAME --password-env VAR] [--force]`

Creates what the named gateways and the driver lack to talk securely (see
`hrc_gateway.pki` for the layout): the driver's certificate once, each
gateway's certificate, the mutual trust, and optionally a gateway user.
Run it again at will: it keeps what exists and re-pins each gateway's
current certificate. It replaces a gateway's certificate only with --force;
asking for other --host names than an existing certificate has counts as
replacing it. The password comes from an environment variable, never from
the command line, where `ps` and the shell history would show it.
"""

from __future__ import annotations

import ipaddress
import os
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from django.conf import settings
from django.core.management.base import BaseCommand, CommandError, CommandParser

from hrc_gateway import pki


class Command(BaseCommand):
    help = (
        "Creates the certificates, trust lists and users the cobot gateways and the driver "
        "need; keeps what exists."
    )

    def add_arguments(self, parser: CommandParser) -> None:
        parser.add_argument(
            "cobots", nargs="+", metavar="cobot", help="Gateway names, e.g. cobot1."
        )
        parser.add_argument(
            "--pki", type=Path, help="Certificate directory (default settings.HRC_PKI_DIR)."
        )
        parser.add_argument(
            "--host",
            action="append",
            dest="hosts",
            help=(
                "A DNS name or IP address clients reach the gateways by (repeat; default "
                f"{', '.join(pki.DEFAULT_GATEWAY_HOSTS)}). Applies to every cobot named."
            ),
        )
        parser.add_argument("--user", help="Add this user to each named gateway.")
        parser.add_argument(
            "--password-env",
            metavar="VAR",
            help="The environment variable holding the --user's password.",
        )
        parser.add_argument(
            "--force",
            action="store_true",
            help="Replace the named gateways' certificates (and an incomplete driver certificate).",
        )

    def handle(self, *args: Any, **options: Any) -> None:
        try:
            self._run(options)
        except pki.PkiError as error:
            raise CommandError(str(error)) from None

    def _run(self, options: dict[str, Any]) -> None:
        cobots: list[str] = list(dict.fromkeys(options["cobots"]))
        for cobot in cobots:
            pki.check_cobot_name(cobot)
        # Read the password before writing anything, so a typo leaves no half-done state.
        user = _user(options["user"], options["password_env"])
        pki_dir: Path = options["pki"] or _default_pki_dir()
        self._ensure_driver(pki_dir, options["force"])
        for cobot in cobots:
            self._ensure_gateway(pki_dir, cobot, options["hosts"], options["force"])
            accepted, pinned = pki.trust_each_other(pki_dir, cobot)
            self.stdout.write(f"{cobot}: the gateway trusts {accepted}; the driver pins {pinned}")
            users_file = pki.gateway_files(pki_dir, cobot).users
            if user is not None:
                pki.add_gateway_user(pki_dir, cobot, *user)
                self.stdout.write(f"{cobot}: user {user[0]} saved in {users_file}")
            elif not users_file.exists():
                self.stdout.write(
                    self.style.WARNING(
                        f"{cobot}: no users yet; the gateway will not start secured until one is "
                        "added with --user NAME --password-env VAR"
                    )
                )

    def _ensure_driver(self, pki_dir: Path, force: bool) -> None:
        files = pki.driver_files(pki_dir)
        if files.cert.exists() and files.key.exists():
            # Never replaced here: every gateway trusts it; replacing it is
            # deleting driver/ and running this for every cobot.
            self.stdout.write(f"driver: keeping {files.cert}")
            return
        if (files.cert.exists() or files.key.exists()) and not force:
            raise CommandError(
                f"The driver certificate in {files.folder} is incomplete (a certificate without "
                "its key or the reverse); pass --force to make a new one."
            )
        pki.make_driver_certificate(pki_dir, force=True)
        self.stdout.write(self.style.SUCCESS(f"driver: created {files.cert} and {files.key}"))

    def _ensure_gateway(
        self, pki_dir: Path, cobot: str, hosts: Sequence[str] | None, force: bool
    ) -> None:
        files = pki.gateway_files(pki_dir, cobot)
        if not force and files.cert.exists() and files.key.exists():
            if hosts and pki.certificate_hosts(files.cert) != {_canonical(host) for host in hosts}:
                raise CommandError(
                    f"{cobot}: {files.cert} exists for other hosts "
                    f"({', '.join(sorted(pki.certificate_hosts(files.cert)))}); "
                    "pass --force to replace it."
                )
            self.stdout.write(f"{cobot}: keeping {files.cert}")
            return
        if not force and (files.cert.exists() or files.key.exists()):
            raise CommandError(
                f"{cobot}: the certificate in {files.folder} is incomplete; pass --force to make a new one."
            )
        pki.make_gateway_certificate(
            pki_dir, cobot, hosts or pki.DEFAULT_GATEWAY_HOSTS, force=force
        )
        self.stdout.write(self.style.SUCCESS(f"{cobot}: created {files.cert} and {files.key}"))


def _default_pki_dir() -> Path:
    # HRC_PKI_DIR is the setting the gateway and driver read too; VAR_DIR / "pki" is its default.
    return Path(getattr(settings, "HRC_PKI_DIR", settings.VAR_DIR / "pki"))


def _canonical(host: str) -> str:
    """The host as the certificate spells it: IP addresses in their short form."""
    try:
        return str(ipaddress.ip_address(host))
    except ValueError:
        return host


def _user(username: str | None, password_env: str | None) -> tuple[str, str] | None:
    """The (name, password) to add, or None; raises CommandError when only half is given."""
    if username is None and password_env is None:
        return None
    if username is None or password_env is None:
        raise CommandError("--user and --password-env go together.")
    pki.check_username(username)
    password = os.environ.get(password_env)
    if not password:
        raise CommandError(f"The environment variable {password_env} is not set or empty.")
    return username, password
