"""The organisation's administration for its admins: /organisation/people/, teams/, cells/.

An admin is a member with the admin role in the organisation they work in
(hrc.navigation.current_membership); no Django staff flag. Everyone else gets a
403 page, and an id of another organisation's person, team or cell is a 404.
Every write goes through hrc.organisations.services, which keeps the record
shown at the foot of each page.
"""

from __future__ import annotations

from typing import Any

from django.contrib.auth.decorators import login_required
from django.contrib.auth.forms import SetPasswordForm
from django.contrib.auth.models import User
from django.core.exceptions import ValidationError
from django.http import Http404, HttpRequest, HttpResponse, HttpResponseRedirect
from django.shortcuts import render
from django.urls import reverse
from django.utils.encoding import force_str
from django.utils.http import urlsafe_base64_decode
from django.views.decorators.http import require_http_methods, require_POST

from hrc.errors import NotAllowed
from hrc.navigation import current_membership
from hrc.organisations import hooks, selectors, services
from hrc.organisations.choices import Role
from hrc.organisations.forms import (
    CellDescriptionForm,
    CellForm,
    MemberForm,
    PersonForm,
    TeamForm,
)
from hrc.organisations.models import Cell, Membership, Organisation, Team

ADMINS_ONLY = "Only the organisation's admins manage its people, teams and cells."
RECORDS_SHOWN = 10


def _admin_of(request: HttpRequest) -> Membership:
    """The admin's membership in the organisation they work in; NotAllowed for anyone else."""
    membership = current_membership(request)
    if membership is None or membership.role != Role.ADMIN:
        raise NotAllowed(ADMINS_ONLY)
    return membership


def _page(
    request: HttpRequest, template: str, organisation: Organisation, **context: Any
) -> HttpResponse:
    status = context.pop("status", 200)
    context |= {
        "organisation": organisation,
        "records": selectors.admin_records_of(organisation.pk)[:RECORDS_SHOWN],
        "page": template.rsplit("/", 1)[-1].removesuffix(".html"),
    }
    return render(request, template, context, status=status)


def admins_only(view: Any) -> Any:
    """Signed in and an admin of the current organisation, which is passed to the view."""

    @login_required
    def wrapped(request: HttpRequest, *args: Any, **kwargs: Any) -> HttpResponse:
        result: HttpResponse = view(request, _admin_of(request), *args, **kwargs)
        return result

    wrapped.__name__ = view.__name__
    wrapped.__doc__ = view.__doc__
    return wrapped


# People --------------------------------------------------------------------------


@require_http_methods(["GET", "POST"])
@admins_only
def people(request: HttpRequest, admin: Membership) -> HttpResponse:
    """The members with role, teams and state; adding a person shows their password once."""
    organisation = admin.organisation
    form = PersonForm(organisation, request.POST or None)
    added: dict[str, str] | None = None
    status = 200
    if request.method == "POST":
        if form.is_valid():
            try:
                membership, password = services.add_person(
                    organisation,
                    by=admin.user,
                    **form.cleaned_data,
                )
            except ValidationError as error:
                form.add_service_errors(error)
            else:
                added = {"username": membership.user.username, "password": password}
                if not password:
                    added["invitation"] = request.build_absolute_uri(
                        reverse("organisation:join", args=services.invitation_for(membership.user))
                    )
                form = PersonForm(organisation)
        if not form.is_valid() and added is None:
            status = 400
    return _page(
        request, "organisations/people.html", organisation,
        members=selectors.members_of(organisation.pk), form=form, added=added, status=status,
    )  # fmt: skip


def _member(admin: Membership, pk: int) -> Membership:
    membership = selectors.members_of(admin.organisation_id).filter(pk=pk).first()
    if membership is None:
        raise Http404("No such person in your organisation.")
    return membership


@require_http_methods(["GET", "POST"])
@admins_only
def person(request: HttpRequest, admin: Membership, pk: int) -> HttpResponse:
    """One member: change their role and teams, reset their password, deactivate them."""
    membership = _member(admin, pk)
    organisation = admin.organisation
    initial = {"role": membership.role, "teams": list(membership.teams.all())}
    form = MemberForm(organisation, request.POST or None, initial=initial)
    status = 200
    if request.method == "POST":
        if form.is_valid():
            try:
                _change_member(membership, form.cleaned_data, by=admin.user)
            except ValidationError as error:
                form.add_service_errors(error)
            else:
                return HttpResponseRedirect(reverse("organisation:person", args=[pk]))
        status = 400
    return _page(
        request, "organisations/person.html", organisation,
        member=membership, form=form, status=status,
    )  # fmt: skip


def _change_member(membership: Membership, data: dict[str, Any], *, by: User) -> None:
    if data["role"] != membership.role:
        services.change_member_role(membership, data["role"], by=by)
    if set(data["teams"]) != set(membership.teams.all()):
        services.set_member_teams(membership, data["teams"], by=by)


@require_POST
@admins_only
def deactivate_person(request: HttpRequest, admin: Membership, pk: int) -> HttpResponse:
    """Deactivates the member; their open tasks go back to their candidates."""
    membership = _member(admin, pk)
    try:
        handed_back = services.deactivate_member(membership, by=admin.user)
    except ValidationError as error:
        return _page(
            request, "organisations/person.html", admin.organisation,
            member=membership, form=MemberForm(admin.organisation, initial={"role": membership.role, "teams": list(membership.teams.all())}),
            refusal=" ".join(error.messages), status=400,
        )  # fmt: skip
    return _page(
        request, "organisations/person.html", admin.organisation,
        member=membership, form=None,
        notice=f"{membership.user.username} is deactivated; {handed_back} open task(s) went back to their team.",
    )  # fmt: skip


@require_POST
@admins_only
def reset_password(request: HttpRequest, admin: Membership, pk: int) -> HttpResponse:
    """Sets a new one-time password and shows it, once."""
    membership = _member(admin, pk)
    try:
        password = services.reset_member_password(membership, by=admin.user)
    except ValidationError as error:
        raise Http404(" ".join(error.messages)) from None
    form = MemberForm(
        admin.organisation,
        initial={"role": membership.role, "teams": list(membership.teams.all())},
    )
    return _page(
        request, "organisations/person.html", admin.organisation,
        member=membership, form=form, password=password,
    )  # fmt: skip


# Teams ---------------------------------------------------------------------------


@require_http_methods(["GET", "POST"])
@admins_only
def teams(request: HttpRequest, admin: Membership) -> HttpResponse:
    """The teams with their members, and a form for a new one."""
    organisation = admin.organisation
    form = TeamForm(organisation, request.POST or None)
    status = 200
    if request.method == "POST":
        if form.is_valid():
            try:
                services.add_team(organisation, by=admin.user, **form.cleaned_data)
            except ValidationError as error:
                form.add_service_errors(error)
            else:
                return HttpResponseRedirect(reverse("organisation:teams"))
        status = 400
    return _page(
        request, "organisations/teams.html", organisation,
        teams=selectors.teams_of(organisation.pk), form=form, status=status,
    )  # fmt: skip


def _team(admin: Membership, pk: int) -> Team:
    team = selectors.teams_of(admin.organisation_id).filter(pk=pk).first()
    if team is None:
        raise Http404("No such team in your organisation.")
    return team


@require_http_methods(["GET", "POST"])
@admins_only
def team(request: HttpRequest, admin: Membership, pk: int) -> HttpResponse:
    """One team: rename it, choose its members, or delete it."""
    found = _team(admin, pk)
    organisation = admin.organisation
    initial = {"name": found.name, "members": list(found.members.all())}
    form = TeamForm(organisation, request.POST or None, initial=initial)
    status = 200
    if request.method == "POST":
        if "delete" in request.POST:
            services.remove_team(found, by=admin.user)
            return HttpResponseRedirect(reverse("organisation:teams"))
        if form.is_valid():
            try:
                services.change_team(found, by=admin.user, **form.cleaned_data)
            except ValidationError as error:
                form.add_service_errors(error)
            else:
                return HttpResponseRedirect(reverse("organisation:teams"))
        status = 400
    return _page(
        request, "organisations/team.html", organisation, team=found, form=form, status=status
    )


# Cells ---------------------------------------------------------------------------


@require_http_methods(["GET", "POST"])
@admins_only
def cells(request: HttpRequest, admin: Membership) -> HttpResponse:
    """The cells with the cobots in each and their tablets, and a form for a new one."""
    organisation = admin.organisation
    form = CellForm(organisation, request.POST or None)
    status = 200
    if request.method == "POST":
        if form.is_valid():
            try:
                services.add_cell(organisation, by=admin.user, **form.cleaned_data)
            except ValidationError as error:
                form.add_service_errors(error)
            else:
                return HttpResponseRedirect(reverse("organisation:cells"))
        status = 400
    rows = [
        {"cell": cell, "occupants": hooks.cell_occupants(organisation.pk, cell.name)}
        for cell in selectors.cells_of(organisation.pk)
    ]
    return _page(
        request, "organisations/cells.html", organisation, rows=rows, form=form, status=status
    )


def _cell(admin: Membership, pk: int) -> Cell:
    cell = selectors.cells_of(admin.organisation_id).filter(pk=pk).first()
    if cell is None:
        raise Http404("No such cell in your organisation.")
    return cell


@require_http_methods(["GET", "POST"])
@admins_only
def cell(request: HttpRequest, admin: Membership, pk: int) -> HttpResponse:
    """One cell: change its description, or delete it when no cobot stands in it."""
    found = _cell(admin, pk)
    organisation = admin.organisation
    form = CellDescriptionForm(
        organisation, request.POST or None, initial={"description": found.description}
    )
    status = 200
    refusal = ""
    if request.method == "POST":
        if "delete" in request.POST:
            try:
                services.remove_cell(found, by=admin.user)
            except ValidationError as error:
                refusal, status = " ".join(error.messages), 400
            else:
                return HttpResponseRedirect(reverse("organisation:cells"))
        elif form.is_valid():
            try:
                services.describe_cell(found, by=admin.user, **form.cleaned_data)
            except ValidationError as error:
                form.add_service_errors(error)
            else:
                return HttpResponseRedirect(reverse("organisation:cells"))
            status = 400
        else:
            status = 400
    return _page(
        request, "organisations/cell.html", organisation,
        cell=found, form=form, refusal=refusal, status=status,
        occupants=hooks.cell_occupants(organisation.pk, found.name),
    )  # fmt: skip


# The invitation link -------------------------------------------------------------


@require_http_methods(["GET", "POST"])
def join(request: HttpRequest, uidb64: str, token: str) -> HttpResponse:
    """Where an invited person chooses their password, once, before the link expires."""
    try:
        uid = force_str(urlsafe_base64_decode(uidb64))
    except (ValueError, TypeError):
        uid = ""
    # ASCII digits only: int() would also read "٣" as 3, a link Django never wrote.
    user = User.objects.filter(pk=int(uid)).first() if uid.isascii() and uid.isdigit() else None
    if user is None or not services.invitation_valid(user, token):
        context = {"message": "This invitation link has been used or has expired: ask your admin for a new one."}  # fmt: skip
        return render(request, "organisations/join.html", context, status=404)
    form = SetPasswordForm(user, request.POST or None)
    if request.method == "POST" and form.is_valid():
        try:
            services.accept_invitation(user, token, form.cleaned_data["new_password1"])
        except ValidationError as error:
            form.add_error(None, error.messages)
        else:
            return HttpResponseRedirect(reverse("login") + "?joined=1")
    status = 400 if form.errors else 200
    return render(request, "organisations/join.html", {"form": form, "person": user}, status=status)
