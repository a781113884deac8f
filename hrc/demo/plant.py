"""The demo as a living plant: its cobots made ready as a person at the cell would, cases started.

A plant's cobots boot powered off. Before a shift a person at the teach
pendant powers each on and releases its brakes; that is never hrc's
decision, so the demo does it here, beside hrc, the way that person would
(straight to the cobot's gateway, as the pendant is), and says so. hrc then
loads each step's program itself.

The demo's cases are started through the running server, as an engineer
would through the API: on the embedded default a job sent from this
process would run on this process's threads, not the web server's.
"""

from __future__ import annotations

import json
import urllib.error
import urllib.request
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Final

from django.contrib.auth.models import User
from rest_framework.authtoken.models import Token

from hrc.cobots.drivers.base import DriverError
from hrc.cobots.drivers.runner import driver_for
from hrc.organisations.models import Organisation
from hrc.patterns.models import PatternModel
from hrc.patterns.selectors import latest_version

# Powering on, booting and releasing the brakes take a UR5e (and the simulator at
# --time-scale 1) several seconds.
POWER_ON_TIMEOUT: Final = 60.0


@dataclass(frozen=True)
class DemoCase:
    """A use case the demo starts a case of, on one of its cobots."""

    file: str  # in hrc/patterns/examples/use_cases/
    cobot: str


# Two cobots, two use cases without a choice an operator must think about twice:
# polishing (six lines, the operator a line behind the cobot) and pick & place.
DEMO_CASES: Final = (
    DemoCase("5_polishing.json", "cobot1"),
    DemoCase("3_pick_and_place.json", "cobot2"),
)


def prepare_cobots(endpoints: Mapping[str, str]) -> list[str]:
    """Powers each cobot on and releases its brakes, as the person at the pendant; banner lines.

    A cobot that refuses (a protective stop kept from an earlier run) is named
    with what to do; the demo serves all the same.
    """
    lines = []
    for name, endpoint in endpoints.items():
        try:
            driver_for(name, endpoint).call("PowerOn", timeout=POWER_ON_TIMEOUT)
        except DriverError as error:
            lines.append(f"  {name}: not powered on ({error}) Its cases wait; see /cobots/.")
        else:
            lines.append(
                f"  {name}: powered on and brakes released, as a person at the pendant would; "
                "hrc loads each step's program"
            )
    return lines


def start_cases(url: str, engineer: User, organisation: Organisation, folder: Path) -> list[str]:
    """Starts a case of each DEMO_CASES use case through the server at `url`; banner lines."""
    token, _ = Token.objects.get_or_create(user=engineer)
    lines = []
    for demo_case in DEMO_CASES:
        name = json.loads((folder / demo_case.file).read_text(encoding="utf-8"))["name"]
        pattern = PatternModel.objects.filter(organisation=organisation, name=name).first()
        version = latest_version(pattern) if pattern is not None else None
        if version is None:
            lines.append(f"  {name}: not started (not published)")
            continue
        body = {"version": version.pk, "actor_mapping": {"c": {"cobot": demo_case.cobot}}}
        try:
            case = _post(f"{url}/api/cases/", body, token.key)
        except (OSError, ValueError) as error:
            lines.append(f"  {name}: not started ({error})")
            continue
        lines.append(f"  {name} on {demo_case.cobot}: case {case['id']}  {url}/cases/{case['id']}/")
    return lines


def _post(url: str, body: object, token: str) -> dict[str, object]:
    request = urllib.request.Request(
        url,
        data=json.dumps(body).encode(),
        headers={"Content-Type": "application/json", "Authorization": f"Token {token}"},
        method="POST",
    )
    try:
        with urllib.request.urlopen(request, timeout=30) as response:
            answer: dict[str, object] = json.loads(response.read())
    except urllib.error.HTTPError as error:
        raise ValueError(f"HTTP {error.code}: {error.read().decode(errors='replace')}") from None
    return answer
