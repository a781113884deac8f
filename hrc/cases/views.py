"""The supervisor pages: running cases, one case (its net with the live marking, timeline,
interruptions, incidents), and the open incidents of the organisation.

For engineers and admins, behind the API's organisation wall: a case of
another organisation is a 404 whatever its id; in the user's organisation
but without a writer's role, a 403. The pages only read. Resolving an
incident is the page script's POST to the REST API (frontend/src/supervisor/),
so the services' checks and refusal messages stay in one place; the same
script keeps the marking, timeline and incidents up to date.
"""

from __future__ import annotations

import datetime as dt
import json
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from functools import lru_cache
from typing import Any
from urllib.parse import urlencode

from django.contrib.auth.decorators import login_required
from django.contrib.auth.models import User
from django.core.exceptions import ValidationError
from django.core.paginator import Paginator
from django.http import Http404, HttpRequest, HttpResponse
from django.shortcuts import redirect, render
from django.urls import reverse
from django.utils import timezone
from django.views.decorators.http import require_POST

from hrc.cases import selectors, services
from hrc.cases.choices import (
    COMMANDED_MODES,
    OPEN_CASE_STATUSES,
    OPEN_WORK_ITEM_STATES,
    CaseStatus,
    EventType,
    JobState,
    WorkItemKind,
    WorkItemState,
)
from hrc.cases.drawing import ConstraintLine, NetDrawing, Node, draw_net
from hrc.cases.forms import MappingForm, StartForm, StartRightsForm
from hrc.cases.models import Case, CaseEvent, Incident, Interruption, Job, Message, WorkItem
from hrc.cases.nets import case_net
from hrc.errors import Invalid, NotAllowed
from hrc.organisations.choices import Role
from hrc.organisations.selectors import cells_of, may_write_in, writable_organisations
from hrc.patterns.models import PatternVersion
from hrc.patterns.selectors import versions_visible_to, why_may_not_start
from hrc.patterns.services import retire_version, set_start_rights

CASES_PER_PAGE = 50
INCIDENTS_PER_PAGE = 50
# A long case keeps thousands of events; a page shows this many, newest first.
EVENTS_PER_PAGE = 50

SUPERVISORS_ONLY = "Only engineers and admins of the organisation supervise its cases."
# The list's filter: `open` (running or suspended, the default), one status, or `all`.
STATE_FILTERS: dict[str, frozenset[str] | None] = {
    "open": frozenset(OPEN_CASE_STATUSES),
    **{status: frozenset({status}) for status in CaseStatus.values},
    "all": None,
}
EVENT_NAMES = dict(EventType.choices)
# The live socket (hrc/live/routing.py): the pages' doorbell for changes.
LIVE_SOCKET = "/ws/live/"


# Running cases -----------------------------------------------------------------------------


@login_required
def case_list(request: HttpRequest) -> HttpResponse:
    """The cases of the user's organisations, open ones by default; `?state=` filters."""
    _require_supervisor(request)
    state = request.GET.get("state", "open")
    if state not in STATE_FILTERS:
        raise Invalid(f"state must be one of {', '.join(STATE_FILTERS)}, not {state!r}.")
    cases = selectors.supervised_cases(request.user)
    version = request.GET.get("version", "")
    if version.isascii() and version.isdigit() and len(version) <= 18:
        cases = cases.filter(version_id=int(version))
    statuses = STATE_FILTERS[state]
    if statuses is not None:
        cases = cases.filter(status__in=sorted(statuses))
    page = Paginator(cases, CASES_PER_PAGE).get_page(request.GET.get("page"))
    return render(
        request,
        "cases/case_list.html",
        {"page": page, "state": state, "states": list(STATE_FILTERS), "version": version},
    )


def _require_supervisor(request: HttpRequest) -> None:
    if not writable_organisations(request.user).exists():
        raise NotAllowed(SUPERVISORS_ONLY)


# One case ----------------------------------------------------------------------------------


@dataclass(frozen=True)
class DrawnPlace:
    node: Node
    tokens: int


@dataclass(frozen=True)
class DrawnTask:
    node: Node
    state: str
    """running, offered, incident (an open incident about it), or empty."""


@dataclass(frozen=True)
class DrawnConstraint:
    line: ConstraintLine
    tokens: int


@dataclass(frozen=True)
class TimelineRow:
    seq: int
    at: dt.datetime
    who: str
    what: str
    type: str
    task: str
    task_label: str
    change: list[str]
    detail: str


@dataclass(frozen=True)
class InterruptionRow:
    interruption: Interruption
    seconds: float
    ongoing: bool

    @property
    def duration(self) -> str:
        return format_duration(self.seconds)

    @property
    def awaits_leaving(self) -> bool:
        """A cobot paused or slowed for an operator whose task was cancelled: it waits for
        someone to say the operator has left the area (services.confirm_left_area)."""
        held = self.interruption
        return (
            self.ongoing
            and held.mode in COMMANDED_MODES
            and held.by_work_item.state == WorkItemState.CANCELLED
        )


@login_required
def case_detail(request: HttpRequest, pk: int) -> HttpResponse:
    """One case: its net with the marking, open tasks, incidents, interruptions, the messages it
    sent and took, and its timeline."""
    case = _supervised_case(request, pk)
    before = _seq_param(request, "before")
    drawing = _drawing(case.version.pk, case.version)
    items = list(
        selectors.work_items_visible_to(request.user).filter(
            case=case, state__in=sorted(OPEN_WORK_ITEM_STATES)
        )
    )
    incidents = list(selectors.incidents_of(case))
    events, older = _timeline_page(case, before, drawing.labels)
    context = {
        "case": case,
        "drawing": drawing,
        "places": [DrawnPlace(n, case.marking.get(n.id, 0)) for n in drawing.places],
        "tasks": _drawn_tasks(drawing, case.marking, items, incidents),
        "constraints": [
            DrawnConstraint(line, sum(case.marking.get(p, 0) for p in line.places))
            for line in drawing.constraints
        ],
        "work_rows": [work_row(item) for item in items],
        "timers": [
            WaitingTimer(timer.due_at, drawing.labels.get(timer.transition, timer.transition))
            for timer in selectors.armed_timers_of(case)
        ],
        "incidents": incidents,
        "interruptions": _interruption_rows(selectors.interruptions_of(case)),
        "case_messages": _message_rows(case, selectors.messages_of(case)),
        "events": events,
        "before": before,
        "older": older,
        "script": {
            "page": "case",
            "organisations": [case.organisation_id],
            "socket": LIVE_SOCKET,
            "case": case.pk,
            "lastSeq": case.last_seq,
            # Only the newest page grows with new events; an older page stays as it is.
            "live": before is None,
            "labels": drawing.labels,
            "api": {
                "case": reverse("case-detail", args=[case.pk]),
                "events": reverse("case-events", args=[case.pk]),
                "incidents": f"{reverse('incident-list')}?case={case.pk}&all=1",
                "resolve": reverse("incident-resolve", args=[0]),
                "workItems": reverse("work-item-list"),
            },
        },
    }
    return render(request, "cases/case_detail.html", context)


@dataclass(frozen=True)
class WaitingTimer:
    due_at: dt.datetime
    label: str  # the timer transition's


@dataclass(frozen=True)
class WorkRow:
    task: str
    label: str
    state: str
    who: str
    job: str
    id: int
    reassignable: bool  # an operator task still open: a supervisor may hand it over


def work_row(item: WorkItem) -> WorkRow:
    """An open work item as the page lists it (render.ts's workRow says it the same way)."""
    job = getattr(item, "job", None)  # operator tasks have none
    who = item.claimed_by.get_username() if item.claimed_by else ""
    if not who and item.cobot is not None:
        who = item.cobot.name
    if not who and item.device is not None:
        who = item.device.name
    reassignable = item.kind == WorkItemKind.OPERATOR and item.state in OPEN_WORK_ITEM_STATES
    label = item.label or item.task
    return WorkRow(item.task, label, item.state, who or "–", _job_text(item, job), item.pk, reassignable)  # fmt: skip


def _job_text(item: WorkItem, job: Job | None) -> str:
    if job is None:
        return ""
    position = getattr(item, "queue_position", None)  # annotated by the selector
    if job.state == JobState.QUEUED:
        text = f"queued, position {position}" if position is not None else "queued"
        return f"{text}; waiting for {job.waiting_for}" if job.waiting_for else text
    if job.state == JobState.RUNNING:
        return f"running, attempt {job.attempt}"
    return f"{job.state}: {job.last_error}" if job.last_error else str(job.state)


@lru_cache(maxsize=256)
def _drawing(version_id: int, version: PatternVersion) -> NetDrawing:
    # Keyed by id: a published version never changes, so neither does its drawing.
    return draw_net(case_net(version).pattern)


def _supervised_case(request: HttpRequest, pk: int) -> Case:
    """The case if the user may see it (else 404, as the API) and supervise it (else 403)."""
    case = selectors.cases_visible_to(request.user).filter(pk=pk).first()
    if case is None:
        raise Http404("No such case.")
    if not may_write_in(request.user, case.organisation_id):
        raise NotAllowed(SUPERVISORS_ONLY)
    return case


def _seq_param(request: HttpRequest, name: str) -> int | None:
    value = request.GET.get(name)
    if value is None:
        return None
    if not value.isascii() or not value.isdigit() or len(value) > 9:
        raise Invalid(f"{name} must be an event number (a whole number), not {value!r}.")
    return int(value)


def _drawn_tasks(
    drawing: NetDrawing,
    marking: Mapping[str, int],
    items: Iterable[WorkItem],
    incidents: Iterable[Incident],
) -> list[DrawnTask]:
    offered = {
        item.task for item in items if item.state in {WorkItemState.OFFERED, WorkItemState.CLAIMED}
    }
    troubled = {
        incident.work_item.task
        for incident in incidents
        if incident.resolved_at is None and incident.work_item is not None
    }
    drawn = []
    for node in drawing.transitions:
        if node.id in troubled:
            state = "incident"
        elif marking.get(f"running:{node.id}", 0) > 0:
            state = "running"
        elif node.id in offered:
            state = "offered"
        else:
            state = ""
        drawn.append(DrawnTask(node, state))
    return drawn


def _timeline_page(
    case: Case, before: int | None, labels: Mapping[str, str]
) -> tuple[list[TimelineRow], int | None]:
    """The page of events before `before` (the newest when None), newest first, and the
    `before` of the next older page (None on the first event's page)."""
    events = selectors.events_of(case)
    if before is not None:
        events = events.filter(seq__lt=before)
    page = list(events.order_by("-seq")[:EVENTS_PER_PAGE])
    older = page[-1].seq if page and page[-1].seq > 1 else None
    return [timeline_row(event, labels) for event in page], older


def timeline_row(event: CaseEvent, labels: Mapping[str, str]) -> TimelineRow:
    return TimelineRow(
        seq=event.seq,
        at=event.at,
        who=event.user.get_username() if event.user else (event.actor or "hrc"),
        what=EVENT_NAMES.get(event.type, event.type),
        type=event.type,
        task=event.task,
        task_label=labels.get(event.task, event.task),
        change=marking_change(event.marking_before, event.marking_after),
        detail=", ".join(f"{key}: {_short(value)}" for key, value in event.detail.items()),
    )


def marking_change(before: Mapping[str, int], after: Mapping[str, int]) -> list[str]:
    """What an event did to the marking, place by place: ["p1 −1", "running:to1 +1"]."""
    changes = []
    for place in sorted(set(before) | set(after)):
        delta = after.get(place, 0) - before.get(place, 0)
        if delta:
            changes.append(f"{place} {'+' if delta > 0 else '−'}{abs(delta)}")
    return changes


def _short(value: Any) -> str:
    text = value if isinstance(value, str) else json.dumps(value, sort_keys=True)
    return text if len(text) <= 80 else text[:79] + "…"


def _interruption_rows(interruptions: Iterable[Interruption]) -> list[InterruptionRow]:
    now = timezone.now()
    return [
        InterruptionRow(i, ((i.ended_at or now) - i.started_at).total_seconds(), i.ended_at is None)
        for i in interruptions
    ]


@dataclass(frozen=True)
class MessageRow:
    message: Message
    sent: bool  # by this case; else taken by it
    from_: str  # who sent it: this case's transition, another case, or from outside
    to: str  # who took it, or what became of it
    correlation: str  # its keys, as JSON


def _message_rows(case: Case, messages: Iterable[Message]) -> list[MessageRow]:
    now = timezone.now()
    rows = []
    for message in messages:
        source = message.sent_from_case
        sender = (
            _transition_of(message.sent_from_transition, source, case)
            if source is not None
            else "from outside"
        )
        if message.case is not None:
            taker = _transition_of(message.transition, message.case, case)
        else:
            taker = "waiting" if message.expires_at > now else "expired, nobody took it"
        keys = json.dumps(message.correlation, sort_keys=True)
        rows.append(MessageRow(message, source == case, sender, taker, keys))
    return rows


def _transition_of(transition: str, of: Case, this: Case) -> str:
    return transition if of == this else f"{transition} of case {of.pk}"


def format_duration(seconds: float) -> str:
    """12.3 s, 4 min 05 s, 2 h 03 min."""
    if seconds < 60:
        return f"{seconds:.1f} s"
    whole = int(seconds)
    if whole < 3600:
        return f"{whole // 60} min {whole % 60:02d} s"
    return f"{whole // 3600} h {whole % 3600 // 60:02d} min"


# Open incidents ----------------------------------------------------------------------------


@login_required
def incident_list(request: HttpRequest) -> HttpResponse:
    """The unresolved incidents of the user's organisations' cases, newest first."""
    _require_supervisor(request)
    incidents = selectors.supervised_incidents(request.user)
    page = Paginator(incidents, INCIDENTS_PER_PAGE).get_page(request.GET.get("page"))
    script = {
        "page": "incidents",
        "organisations": list(writable_organisations(request.user).values_list("pk", flat=True)),
        "socket": LIVE_SOCKET,
        "api": {
            "incidents": reverse("incident-list"),
            "resolve": reverse("incident-resolve", args=[0]),
            "case": reverse("cases:case-detail", args=[0]),
        },
        "live": page.number == 1,
    }
    context = {"page": page, "script": script}
    return render(request, "cases/incident_list.html", context)


# Running a version: its page, starting cases, steering a case ------------------------------


@login_required
def version_detail(request: HttpRequest, pk: int) -> HttpResponse:
    """A published version: its check report, default mapping, start rights, cases, retiring.

    Engineers and admins change the mapping, the start rights and the retiring
    here (POST `form` = mapping, rights, retire or reinstate); each refusal is
    shown at its field and changes nothing.
    """
    version = _supervised_version(request, pk)
    pattern = case_net(version).pattern
    organisation = version.pattern.organisation
    posted = request.POST if request.method == "POST" else None
    which = request.POST.get("form", "")
    mapping_form = MappingForm(
        posted if which == "mapping" else None,
        pattern=pattern,
        organisation=organisation,
        defaults=version.default_actor_mapping,
        prefix="mapping",
    )
    rights_form = StartRightsForm(
        posted if which == "rights" else None,
        roles=list(Role.choices),
        cells=list(cells_of(organisation.pk).values_list("name", flat=True)),
        initial={"roles": version.start_roles, "cells": version.start_cells},
        prefix="rights",
    )
    if posted is not None:
        if which == "mapping" and mapping_form.is_valid():
            try:
                services.set_default_actor_mapping(version, mapping_form.mapping())
                return _saved(request, version, "The default mapping is saved.")
            except Invalid as invalid:
                mapping_form.refuse(invalid)
        elif which == "rights" and rights_form.is_valid():
            try:
                set_start_rights(
                    version,
                    roles=rights_form.cleaned_data["roles"],
                    cells=rights_form.cleaned_data["cells"],
                )
                return _saved(request, version, "Who may start it is saved.")
            except ValidationError as error:
                for field, messages in error.message_dict.items():
                    rights_form.add_error(
                        field.removeprefix("start_") if field.startswith("start_") else None,
                        messages,
                    )
        elif which in ("retire", "reinstate"):
            retire_version(version, retired=which == "retire")
            said = "retired: it starts no new cases" if which == "retire" else "back in service"
            return _saved(request, version, f"Version {version.number} is {said}.")
    cases = selectors.supervised_cases(request.user).filter(version=version)
    context = {
        "version": version,
        "report": version.report,
        "mapping_form": mapping_form,
        "rights_form": rights_form,
        "cases": cases[:CASES_PER_PAGE],
        "case_count": cases.count(),
        "saved": request.GET.get("saved", ""),
    }
    status = 400 if posted is not None else 200
    return render(request, "cases/version_detail.html", context, status=status)


@login_required
def case_start(request: HttpRequest) -> HttpResponse:
    """The start form: `?version=` chosen, the mapping (the version's defaults, overridable for
    these cases), the start data, a reference and a count; all the cases start or none."""
    _require_supervisor(request)
    version_id = request.GET.get("version", "")
    if not version_id:
        return _choose_version(request)
    version = _supervised_version(request, _whole(version_id, "version"))
    net = case_net(version)
    form = StartForm(
        request.POST if request.method == "POST" else None,
        pattern=net.pattern,
        organisation=version.pattern.organisation,
        defaults=version.default_actor_mapping,
        data_defaults=net.initial_data(),
    )
    refusal = why_may_not_start(request.user, version)
    if request.method == "POST" and refusal is None and form.is_valid():
        try:
            cases = services.start_cases(
                version,
                started_by=_user(request),
                actor_mapping=form.mapping(),
                data=form.start_data(),
                reference=form.cleaned_data["reference"],
                count=form.cleaned_data["count"],
            )
        except Invalid as invalid:
            form.refuse(invalid)
        else:
            if len(cases) == 1:
                return redirect("cases:case-detail", cases[0].pk)
            return redirect(f"{reverse('cases:case-list')}?version={version.pk}")
    context = {"version": version, "form": form, "refusal": refusal}
    status = 400 if request.method == "POST" else 200
    return render(request, "cases/case_start.html", context, status=status)


@login_required
@require_POST
def case_control(request: HttpRequest, pk: int) -> HttpResponse:
    """Cancels (`action=cancel`, with `confirm`), suspends or resumes the case, or says the
    operator of its cancelled task `item` has left the area (`action=left-area`), then shows it."""
    case = _supervised_case(request, pk)
    action = request.POST.get("action", "")
    if action == "left-area":
        wanted = _whole(request.POST.get("item", ""), "item")
        item = WorkItem.objects.filter(case=case, pk=wanted).first()
        if item is None:
            raise Invalid(f"Case {case.pk} has no work item {wanted}.")
        services.confirm_left_area(item, by=_user(request))
        return redirect("cases:case-detail", case.pk)
    steer = CASE_ACTIONS.get(action)
    if steer is None:
        raise Invalid(f"action must be one of {', '.join(CASE_ACTIONS)}, not {action!r}.")
    if action == "cancel" and request.POST.get("confirm") != "yes":
        raise Invalid("Tick 'Yes, cancel this case' to cancel it.")
    steer(case, by=_user(request))
    return redirect("cases:case-detail", case.pk)


CASE_ACTIONS: dict[str, Callable[..., Case]] = {
    "cancel": services.cancel_case,
    "suspend": services.suspend_case,
    "resume": services.resume_case,
}


def _choose_version(request: HttpRequest) -> HttpResponse:
    versions = [
        version
        for version in versions_visible_to(request.user)
        .filter(
            retired_at__isnull=True, pattern__organisation__in=writable_organisations(request.user)
        )
        .order_by("pattern__name", "-number")
        if why_may_not_start(request.user, version) is None
    ]
    return render(request, "cases/case_start_choose.html", {"versions": versions})


def _supervised_version(request: HttpRequest, pk: int) -> PatternVersion:
    """The version if the user may see it (else 404) and run it (else 403)."""
    version = versions_visible_to(request.user).filter(pk=pk).first()
    if version is None:
        raise Http404("No such version.")
    if not may_write_in(request.user, version.pattern.organisation_id):
        raise NotAllowed(SUPERVISORS_ONLY)
    return version


def _saved(request: HttpRequest, version: PatternVersion, message: str) -> HttpResponse:
    return redirect(
        f"{reverse('cases:version', args=[version.pk])}?{urlencode({'saved': message})}"
    )


def _whole(value: str, name: str) -> int:
    if not value.isascii() or not value.isdigit() or len(value) > 18:
        raise Invalid(f"{name} must be an id (a whole number), not {value!r}.")
    return int(value)


def _user(request: HttpRequest) -> User:
    assert isinstance(request.user, User)  # login_required
    return request.user
