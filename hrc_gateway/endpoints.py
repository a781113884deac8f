"""What a cobot endpoint points at: one OPC UA server, compared as the network sees it.

Two spellings of the same server (`opc.tcp://LOCALHOST:4840`,
`opc.tcp://[::ffff:127.0.0.1]`, `opc.tcp://127.1:4840`) must count as one
endpoint, or a second organisation could register another organisation's
robot under a new spelling. Pure Python: the gateway, the driver and the
model's checks share it.
"""

from __future__ import annotations

import asyncio
import ipaddress
import re
import socket
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from urllib.parse import urlsplit

SCHEME = "opc.tcp"
# OPC UA's registered port: an endpoint without one is served there.
DEFAULT_PORT = 4840
# Every spelling of this machine: localhost, 127.0.0.0/8, ::1 and the unspecified
# addresses (connecting to 0.0.0.0 or :: reaches the local host on Linux).
LOOPBACK = "loopback"

IPAddress = ipaddress.IPv4Address | ipaddress.IPv6Address
IPNetwork = ipaddress.IPv4Network | ipaddress.IPv6Network

# A DNS name (RFC 1123 labels); anything else as a host is refused rather than guessed at.
_HOST_NAME = re.compile(
    r"(?=.{1,253}\.?$)[A-Za-z0-9_](?:[A-Za-z0-9_-]{0,61}[A-Za-z0-9_])?"
    r"(?:\.[A-Za-z0-9_](?:[A-Za-z0-9_-]{0,61}[A-Za-z0-9_])?)*\.?"
)
# What inet_aton reads as an IPv4 address besides the dotted quad ("127.1", "0x7f.1", "2130706433").
_LEGACY_IPV4 = re.compile(r"[0-9A-Fa-fXx.]+")


class EndpointError(ValueError):
    """The text is not a host or an endpoint this module can compare; the message says why."""


@dataclass(frozen=True)
class EndpointKey:
    """The server an endpoint reaches: scheme, canonical host and port (the default filled in)."""

    scheme: str
    host: str
    port: int

    def __str__(self) -> str:
        host = f"[{self.host}]" if ":" in self.host else self.host
        return f"{self.scheme}://{host}:{self.port}"


def parse_address(host: str) -> IPAddress | None:
    """The IP address a host literal names (bracketed, IPv4-mapped and inet_aton forms too).

    Returns None for a host name, which only DNS can turn into addresses.
    """
    bare = host[1:-1] if host.startswith("[") and host.endswith("]") else host
    try:
        address = ipaddress.ip_address(bare)
    except ValueError:
        if not _LEGACY_IPV4.fullmatch(bare):
            return None
        try:
            address = ipaddress.IPv4Address(socket.inet_aton(bare))
        except OSError:
            return None
    if isinstance(address, ipaddress.IPv6Address) and address.ipv4_mapped is not None:
        return address.ipv4_mapped
    return address


def canonical_host(host: str) -> str:
    """The host as a comparison sees it: LOOPBACK for this machine, an IP in its canonical
    form, else the lower-case name without a trailing dot.

    Raises EndpointError for text that is neither an address nor a DNS name.
    """
    address = parse_address(host)
    if address is not None:
        return LOOPBACK if _is_local(address) else str(address)
    name = host.lower().removesuffix(".")
    if not _HOST_NAME.fullmatch(host):
        raise EndpointError(f"{host!r} is neither a host name nor an IP address.")
    return LOOPBACK if name == "localhost" or name.endswith(".localhost") else name


def host_and_port(endpoint: str) -> tuple[str, int]:
    """The endpoint's host as written (brackets off) and its port (OPC UA's default when none).

    Raises EndpointError when it is no opc.tcp URL with a host.
    """
    try:
        parts = urlsplit(endpoint)
        port = parts.port
    except ValueError as error:
        raise EndpointError(f"{endpoint!r} is not a valid URL: {error}.") from None
    if parts.scheme.lower() != SCHEME:
        raise EndpointError(f"{endpoint!r} does not start with {SCHEME}://.")
    if not parts.hostname:
        raise EndpointError(f"The endpoint {endpoint!r} names no host.")
    return parts.hostname, port or DEFAULT_PORT


def endpoint_key(endpoint: str) -> EndpointKey:
    """The key two registrations of the same server share; raises EndpointError when unparsable."""
    host, port = host_and_port(endpoint)
    return EndpointKey(SCHEME, canonical_host(host), port)


def url_host(host: str) -> str:
    """The host as written in a URL: an IPv6 address in brackets."""
    return f"[{host}]" if ":" in host and not host.startswith("[") else host


def bind_host(host: str) -> str:
    """The address a server binds for `host`: an IPv4-mapped address as plain IPv4, brackets off.

    Raises EndpointError for text that is neither an address nor a DNS name.
    """
    address = parse_address(host)
    if address is not None:
        return str(address)
    canonical_host(host)  # raises for what is no host name
    return host


def resolve(host: str, port: int) -> list[IPAddress]:
    """Every address `host` stands for (itself for an IP literal); raises EndpointError when DNS fails."""
    address = parse_address(host)
    if address is not None:
        return [address]
    try:
        found = socket.getaddrinfo(host, port, type=socket.SOCK_STREAM)
    except (OSError, UnicodeError):
        raise EndpointError(f"The host {host} cannot be resolved.") from None
    return addresses_of(info[4][0] for info in found)


def addresses_of(texts: Iterable[object]) -> list[IPAddress]:
    """getaddrinfo's address strings as addresses (IPv4-mapped ones as IPv4), in order, once each."""
    addresses: list[IPAddress] = []
    for text in texts:
        address = parse_address(str(text).partition("%")[0])
        if address is not None and address not in addresses:
            addresses.append(address)
    return addresses


def outside(addresses: Sequence[IPAddress], networks: Sequence[IPNetwork]) -> list[IPAddress]:
    """Those addresses no network contains; none when no networks are configured (no restriction)."""
    if not networks:
        return []
    return [a for a in addresses if not any(a.version == n.version and a in n for n in networks)]


async def check_networks(endpoint: str, networks: Sequence[IPNetwork]) -> None:
    """Resolves the endpoint's host (without blocking the loop) and raises EndpointError unless
    every address is in one of the networks; no networks: no restriction."""
    if not networks:
        return
    host, port = host_and_port(endpoint)
    address = parse_address(host)
    if address is not None:
        found = [address]
    else:
        try:
            infos = await asyncio.get_running_loop().getaddrinfo(
                host, port, type=socket.SOCK_STREAM
            )
        except (OSError, UnicodeError):
            raise EndpointError(f"The host {host} cannot be resolved.") from None
        found = addresses_of(info[4][0] for info in infos)
    if not found or outside(found, networks):
        raise EndpointError(
            f"The host {host} is outside the networks cobot endpoints may be on "
            "(HRC_COBOT_NETWORKS)."
        )


def _is_local(address: IPAddress) -> bool:
    return address.is_loopback or address.is_unspecified
