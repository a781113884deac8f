"""Admin pages for running cases: read-only views of the rows, steering through hrc.cases.services.

Nothing here saves a case, work item, job or event directly: the rows are the
runtime's truth and the event log is append-only. An admin may cancel,
suspend or resume selected cases; each goes through its service, which takes
the case row lock and writes the event.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from django.contrib import admin, messages
from django.db.models import QuerySet
from django.http import HttpRequest

from hrc.cases import services
from hrc.cases.models import Case, CaseEvent, CaseTimer, Incident, Job, Message, WorkItem
from hrc.errors import Refusal

# Generic for mypy only: Django's runtime classes are not subscriptable.
if TYPE_CHECKING:
    ModelAdminBase = admin.ModelAdmin[Any]
    WorkItemInlineBase = admin.TabularInline[WorkItem, Case]
else:
    ModelAdminBase = admin.ModelAdmin
    WorkItemInlineBase = admin.TabularInline


class ReadOnlyAdmin(ModelAdminBase):
    """Shows rows and never writes them: the runtime's services do."""

    def has_add_permission(self, request: HttpRequest, obj: Any = None) -> bool:
        return False

    def has_change_permission(self, request: HttpRequest, obj: Any = None) -> bool:
        return False

    def has_delete_permission(self, request: HttpRequest, obj: Any = None) -> bool:
        return False


class WorkItemInline(WorkItemInlineBase):
    model = WorkItem
    fields = readonly_fields = ("task", "label", "kind", "state", "claimed_by", "offered_at")
    extra = 0
    can_delete = False
    show_change_link = True

    def has_add_permission(self, request: HttpRequest, obj: Case | None = None) -> bool:
        return False

    def has_change_permission(self, request: HttpRequest, obj: Case | None = None) -> bool:
        return False


def _steer(
    verb: str, change: Callable[[Case, Any], Case]
) -> Callable[[Any, HttpRequest, QuerySet[Case]], None]:
    """An admin action applying a case service to each selected case; refusals become messages."""

    def steer(modeladmin: Any, request: HttpRequest, queryset: QuerySet[Case]) -> None:
        done = 0
        for case in queryset:
            try:
                change(case, request.user)
                done += 1
            except Refusal as refused:
                modeladmin.message_user(request, f"Case {case.pk}: {refused}", messages.WARNING)
        if done:
            modeladmin.message_user(request, f"{done} case(s) {verb}.", messages.SUCCESS)

    steer.__name__ = f"{verb}_cases"
    return admin.action(description=f"{verb.capitalize()} selected cases", permissions=["steer"])(
        steer
    )


@admin.register(Case)
class CaseAdmin(ReadOnlyAdmin):
    list_display = ["id", "version", "organisation", "status", "started_by", "started_at"]
    list_filter = ["status", "organisation"]
    search_fields = ["=id", "version__pattern__name"]
    list_select_related = ["version__pattern", "organisation", "started_by"]
    inlines = [WorkItemInline]
    actions = [
        _steer("cancelled", lambda case, user: services.cancel_case(case, by=user)),
        _steer("suspended", lambda case, user: services.suspend_case(case, by=user)),
        _steer("resumed", lambda case, user: services.resume_case(case, by=user)),
    ]

    def has_steer_permission(self, request: HttpRequest) -> bool:
        # Steering is a change to the case, made by its service, never by the form.
        return request.user.has_perm("cases.change_case")


@admin.register(WorkItem)
class WorkItemAdmin(ReadOnlyAdmin):
    list_display = ["id", "case", "task", "label", "kind", "state", "claimed_by", "offered_at"]
    list_filter = ["kind", "state"]
    search_fields = ["=case__id", "task", "label"]
    list_select_related = ["case", "claimed_by"]


@admin.register(Job)
class JobAdmin(ReadOnlyAdmin):
    list_display = [
        "id", "cobot", "device", "case", "kind", "state", "attempt", "queued_at", "waiting_for",
    ]  # fmt: skip
    list_filter = ["state", "kind", "cobot", "device"]
    search_fields = ["=case__id", "cobot__name", "device__name"]
    list_select_related = ["cobot", "device", "case"]


@admin.register(CaseTimer)
class CaseTimerAdmin(ReadOnlyAdmin):
    list_display = ["id", "case", "transition", "state", "armed_at", "due_at", "ended_at"]
    list_filter = ["state"]
    search_fields = ["=case__id", "transition"]
    list_select_related = ["case"]


@admin.register(Incident)
class IncidentAdmin(ReadOnlyAdmin):
    list_display = ["id", "case", "kind", "message", "opened_at", "resolution", "resolved_at"]
    list_filter = ["kind", "resolution"]
    search_fields = ["=case__id", "message"]
    list_select_related = ["case"]


@admin.register(CaseEvent)
class CaseEventAdmin(ReadOnlyAdmin):
    list_display = ["case", "seq", "type", "task", "user", "at"]
    list_filter = ["type"]
    search_fields = ["=case__id", "task"]
    list_select_related = ["case", "user"]


@admin.register(Message)
class MessageAdmin(ReadOnlyAdmin):
    list_display = [
        "message_id", "name", "organisation", "received_at", "sent_from_case", "case",
        "consumed_at",
    ]  # fmt: skip
    list_filter = ["organisation", "name"]
    search_fields = ["message_id", "name"]
    list_select_related = ["organisation", "case", "sent_from_case"]
