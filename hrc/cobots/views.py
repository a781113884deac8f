"""The cobot pages for engineers and admins: /cobots/, /cobots/<id>/, new/ and <id>/edit/;
and the device pages for admins: /cobots/devices/, devices/new/ and devices/<id>/edit/.

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
from django.contrib.auth.models import User
from django.core.exceptions import ValidationError
from django.core.paginator import Paginator
from django.http import Http404, HttpRequest, HttpResponse, HttpResponseRedirect
from django.shortcuts import render
from django.urls import reverse
from django.views.decorators.http import require_http_methods

from hrc.cobots import control, hooks, services
from hrc.cobots.choices import ControlCommand
from hrc.cobots.forms import CobotForm, CredentialsSecretForm, DeviceForm
from hrc.cobots.models import Cobot, Device
from hrc.cobots.selectors import (
    cobots_visible_to,
    commands_of,
    credentials_secrets_of,
    devices_of,
    devices_visible_to,
    live_state,
)
from hrc.errors import NotAllowed
from hrc.navigation import current_membership
from hrc.organisations.choices import WRITER_ROLES, AdminAction, Role
from hrc.organisations.models import Membership
from hrc.organisations.selectors import is_admin_of, may_write_in, writable_organisations
from hrc.organisations.services import record_admin_action
from hrc_gateway import urua

ENGINEERS_ONLY = "Only engineers and admins of the organisation control its cobots."
ADMINS_ONLY = "Only admins of the organisation set its cobots' credentials."
DEVICE_ADMINS_ONLY = "Only admins of the organisation register, change or deactivate its devices."
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


@login_required
def cobot_list(request: HttpRequest) -> HttpResponse:
    """The cobots of the organisations the user is an engineer or admin of, with state and queue."""
    writable = writable_organisations(request.user)
    if not writable.exists():
        raise NotAllowed(ENGINEERS_ONLY)
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
    return render(request, "cobots/cobot_list.html", {"rows": rows})


@login_required
def cobot_detail(request: HttpRequest, pk: int) -> HttpResponse:
    """One cobot: its state, the control buttons, programs, registers and command record."""
    cobot = cobots_visible_to(request.user).filter(pk=pk).first()
    if cobot is None:
        raise Http404("No such cobot.")
    if not may_write_in(request.user, cobot.organisation_id):
        raise NotAllowed(ENGINEERS_ONLY)
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
        "devices": _with_queues(list(cobot.devices.order_by("name"))),
        "buttons": [{"command": c, "path": p, "label": label} for c, p, label in BUTTONS],
        "script": _script(cobot),
    }
    return render(request, "cobots/cobot_detail.html", context)


@require_http_methods(["GET", "POST"])
@login_required
def cobot_new(request: HttpRequest) -> HttpResponse:
    """Registers a cobot in the organisation the engineer or admin works in."""
    membership = current_membership(request)
    if membership is None or membership.role not in WRITER_ROLES:
        raise NotAllowed(ENGINEERS_ONLY)
    form = CobotForm(request.POST or None, instance=Cobot(organisation=membership.organisation))
    if request.method == "POST" and form.is_valid():
        try:
            cobot = services.create_cobot(membership.organisation, **form.cleaned_data)
        except ValidationError as error:
            form.add_service_errors(error)
        else:
            _record(cobot, request.user, AdminAction.COBOT_REGISTERED, form.cleaned_data)
            return HttpResponseRedirect(reverse("cobots:cobot-detail", args=[cobot.pk]))
    status = 400 if form.errors else 200
    context = {"form": form, "cobot": None}
    return render(request, "cobots/cobot_form.html", context, status=status)


@require_http_methods(["GET", "POST"])
@login_required
def cobot_edit(request: HttpRequest, pk: int) -> HttpResponse:
    """Changes a cobot's settings; the "test" button asks the cobot for its state instead."""
    cobot = cobots_visible_to(request.user).filter(pk=pk).first()
    if cobot is None:
        raise Http404("No such cobot.")
    if not may_write_in(request.user, cobot.organisation_id):
        raise NotAllowed(ENGINEERS_ONLY)
    tested = None
    if request.method == "POST" and "test" in request.POST:
        tested = live_state(cobot)
        form = CobotForm(instance=cobot)
    else:
        form = CobotForm(request.POST or None, instance=cobot)
    if request.method == "POST" and tested is None and form.is_valid():
        changes = {f: form.cleaned_data[f] for f in form.changed_data}
        try:
            services.update_cobot(cobot, **changes)
        except ValidationError as error:
            form.add_service_errors(error)
        else:
            _record(cobot, request.user, AdminAction.COBOT_CHANGED, changes)
            return HttpResponseRedirect(reverse("cobots:cobot-detail", args=[cobot.pk]))
    status = 400 if form.errors else 200
    context = {"form": form, "cobot": cobot, "tested": tested}
    return render(request, "cobots/cobot_form.html", context, status=status)


@require_http_methods(["GET", "POST"])
@login_required
def credentials_secrets(request: HttpRequest) -> HttpResponse:
    """The organisation's credentials secrets, by name only; an admin sets, replaces and
    deletes them. Nobody, the admin included, sees a password again."""
    membership = current_membership(request)
    if membership is None or membership.role != Role.ADMIN:
        raise NotAllowed(ADMINS_ONLY)
    organisation = membership.organisation
    form = CredentialsSecretForm()
    problem = ""
    if request.method == "POST" and "delete" in request.POST:
        secret = credentials_secrets_of(organisation.pk).filter(pk=request.POST["delete"]).first()
        if secret is None:
            raise Http404("No such secret.")
        try:
            services.delete_credentials_secret(secret)
        except ValidationError as error:
            problem = " ".join(error.messages)
        else:
            return HttpResponseRedirect(reverse("cobots:credentials"))
    elif request.method == "POST":
        form = CredentialsSecretForm(request.POST)
        if form.is_valid():
            try:
                services.set_credentials_secret(
                    organisation,
                    form.cleaned_data["name"],
                    username=form.cleaned_data["username"],
                    password=form.cleaned_data["password"],
                    by=request.user if isinstance(request.user, User) else None,
                )
            except ValidationError as error:
                form.add_service_errors(error)
            else:
                return HttpResponseRedirect(reverse("cobots:credentials"))
    context = {
        "form": form,
        "secrets": credentials_secrets_of(organisation.pk),
        "problem": problem,
        "organisation": organisation,
    }
    status = 400 if form.errors or problem else 200
    return render(request, "cobots/credentials.html", context, status=status)


@login_required
def device_list(request: HttpRequest) -> HttpResponse:
    """The organisation's devices by cell, each with its queue (the running call first)."""
    membership = _admin_membership(request)
    devices = _with_queues(list(devices_of(membership.organisation_id)))
    return render(request, "cobots/device_list.html", {"devices": devices})


@require_http_methods(["GET", "POST"])
@login_required
def device_new(request: HttpRequest) -> HttpResponse:
    """Registers a device of one of the organisation's cells, served by one of its cobots."""
    membership = _admin_membership(request)
    form = DeviceForm(request.POST or None, instance=Device(organisation=membership.organisation))
    if request.method == "POST" and form.is_valid():
        try:
            services.create_device(membership.organisation, **form.cleaned_data)
        except ValidationError as error:
            form.add_service_errors(error)
        else:
            return HttpResponseRedirect(reverse("cobots:device-list"))
    status = 400 if form.errors else 200
    return render(request, "cobots/device_form.html", {"form": form, "device": None}, status=status)


@require_http_methods(["GET", "POST"])
@login_required
def device_edit(request: HttpRequest, pk: int) -> HttpResponse:
    """Changes a device; unticking "active" takes it out of service (its queue waits)."""
    device = devices_visible_to(request.user).filter(pk=pk).first()
    if device is None:
        raise Http404("No such device.")
    if not is_admin_of(request.user, device.organisation_id):
        raise NotAllowed(DEVICE_ADMINS_ONLY)
    form = DeviceForm(request.POST or None, instance=device)
    if request.method == "POST" and form.is_valid():
        try:
            services.update_device(device, **{f: form.cleaned_data[f] for f in form.changed_data})
        except ValidationError as error:
            form.add_service_errors(error)
        else:
            return HttpResponseRedirect(reverse("cobots:device-list"))
    status = 400 if form.errors else 200
    return render(
        request, "cobots/device_form.html", {"form": form, "device": device}, status=status
    )


def _admin_membership(request: HttpRequest) -> Membership:
    membership = current_membership(request)
    if membership is None or membership.role != Role.ADMIN:
        raise NotAllowed(DEVICE_ADMINS_ONLY)
    return membership


def _with_queues(devices: list[Device]) -> list[dict[str, Any]]:
    queues = hooks.device_queues([device.pk for device in devices])
    return [{"device": device, "queue": queues[device.pk]} for device in devices]


def _record(cobot: Cobot, by: Any, action: AdminAction, values: dict[str, Any]) -> None:
    # The credentials source names where the secret is, never the secret: safe to record.
    user = by if isinstance(by, User) else None
    record_admin_action(
        cobot.organisation, user, action, cobot.name, {k: str(v) for k, v in values.items()}
    )


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
