"""The cobot pages for engineers and admins: /cobots/ and /cobots/<id>/.

Behind the organisation wall as the supervisor pages are: another
organisation's cobot is a 404 whatever its id; in the organisation without
a writer's role, a 403 page. The pages read; the buttons are the page
script's confirmed POSTs to the REST API (frontend/src/cobots/), so the
checks, the record and the refusal messages stay in hrc.cobots.control.
"""

from __future__ import annotations

import json
from concurrent.futures import ThreadPoolExecutor
from typing import Any

from django.contrib.auth.decorators import login_required
from django.core.paginator import Paginator
from django.http import Http404, HttpRequest, HttpResponse
from django.shortcuts import render
from django.urls import reverse

from hrc.cobots import control, hooks, urua
from hrc.cobots.choices import ControlCommand
from hrc.cobots.models import Cobot
from hrc.cobots.selectors import cobots_visible_to, commands_of, live_state
from hrc.organisations.selectors import may_write_in, writable_organisations

ENGINEERS_ONLY = "Only engineers and admins of the organisation control its cobots."
COMMANDS_PER_PAGE = 20
# Seconds the list waits for each cobot's state; an unreachable one says so instead.
LIST_STATE_TIMEOUT = 1.5
# How often the page script asks for the cobot's state.
REFRESH_SECONDS = 2.0

# The buttons, in the order a person uses them: (command, API path under the cobot, label).
BUTTONS = [
    (ControlCommand.POWER_ON, "power-on", "Power on"),
    (ControlCommand.BRAKE_RELEASE, "brake-release", "Release brakes"),
    (ControlCommand.POWER_OFF, "power-off", "Power off"),
    (ControlCommand.START_PROGRAM, "program/start", "Start program"),
    (ControlCommand.PAUSE_PROGRAM, "program/pause", "Pause program"),
    (ControlCommand.STOP_PROGRAM, "program/stop", "Stop program"),
]


def _refused(request: HttpRequest, status: int, message: str) -> HttpResponse:
    return render(request, "cases/refused.html", {"message": message}, status=status)


@login_required
def cobot_list(request: HttpRequest) -> HttpResponse:
    """The cobots of the organisations the user is an engineer or admin of, with state and queue."""
    writable = writable_organisations(request.user)
    if not writable.exists():
        return _refused(request, 403, ENGINEERS_ONLY)
    cobots = list(
        cobots_visible_to(request.user).filter(organisation__in=writable).order_by("name", "id")
    )
    queues = hooks.queue_lengths([cobot.pk for cobot in cobots])
    with ThreadPoolExecutor(max_workers=8) as pool:
        states = list(pool.map(lambda c: live_state(c, timeout=LIST_STATE_TIMEOUT), cobots))
    rows = [
        {"cobot": cobot, "state": state, "queue": queues[cobot.pk]}
        for cobot, state in zip(cobots, states, strict=True)
    ]
    return render(request, "cobots/cobot_list.html", {"rows": rows, "section": "cobots"})


@login_required
def cobot_detail(request: HttpRequest, pk: int) -> HttpResponse:
    """One cobot: its state, the control buttons, programs, registers and command record."""
    cobot = cobots_visible_to(request.user).filter(pk=pk).first()
    if cobot is None:
        raise Http404("No such cobot.")
    if not may_write_in(request.user, cobot.organisation_id):
        return _refused(request, 403, ENGINEERS_ONLY)
    state = live_state(cobot)
    problems: list[str] = []
    programs = _programs(cobot, problems) if state["reachable"] else []
    registers = _registers(cobot, problems) if state["reachable"] else []
    commands = Paginator(commands_of(cobot), COMMANDS_PER_PAGE).get_page(request.GET.get("page"))
    context = {
        "cobot": cobot,
        "state": state,
        "programs": programs,
        "registers": registers,
        "problems": problems,
        "commands": commands,
        "buttons": [{"command": c, "path": p, "label": label} for c, p, label in BUTTONS],
        "section": "cobots",
        "script": _script(cobot),
    }
    return render(request, "cobots/cobot_detail.html", context)


def _programs(cobot: Cobot, problems: list[str]) -> list[str]:
    try:
        return control.programs(cobot)
    except control.ControlError as error:
        problems.append(f"The programs could not be read: {error}")
        return []


def _registers(cobot: Cobot, problems: list[str]) -> list[dict[str, Any]]:
    """One row per register name: its input and output value."""
    try:
        read = control.read_registers(cobot, urua.all_register_names())
    except control.ControlError as error:
        problems.append(f"The registers could not be read: {error}")
        return []
    return [
        {
            "name": name,
            "input": register_text(read.inputs[name]),
            "output": register_text(read.outputs[name]),
        }
        for name in urua.all_register_names()
    ]


def register_text(value: Any) -> str:
    """A register value as JSON writes it (true, 3, 0.25), as the page script shows it too."""
    return json.dumps(value)


def _script(cobot: Cobot) -> dict[str, Any]:
    """What the page script needs: the cobot and its API's addresses."""
    detail = reverse("cobot-detail", args=[cobot.pk])
    return {
        "cobot": cobot.pk,
        "name": cobot.name,
        "refreshSeconds": REFRESH_SECONDS,
        "api": {
            "base": detail,
            "state": reverse("cobot-state", args=[cobot.pk]),
            "registers": reverse("cobot-registers", args=[cobot.pk]),
            "commands": reverse("cobot-commands", args=[cobot.pk]),
        },
    }
