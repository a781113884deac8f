"""Admin pages for cobots and devices; saves go through hrc.cobots.services."""

from __future__ import annotations

from typing import TYPE_CHECKING

from django.contrib import admin, messages
from django.core.exceptions import PermissionDenied
from django.db.models import QuerySet
from django.forms import BaseModelForm
from django.http import HttpRequest, HttpResponse, HttpResponseRedirect, JsonResponse
from django.shortcuts import get_object_or_404
from django.urls import URLPattern, path, reverse
from django.views.decorators.http import require_POST

from hrc.cobots import selectors, services
from hrc.cobots.models import Cobot, Device

# Generic for mypy only: Django's runtime class is not subscriptable.
if TYPE_CHECKING:
    CobotAdminBase = admin.ModelAdmin[Cobot]
    DeviceAdminBase = admin.ModelAdmin[Device]
else:
    CobotAdminBase = admin.ModelAdmin
    DeviceAdminBase = admin.ModelAdmin


@admin.register(Cobot)
class CobotAdmin(CobotAdminBase):
    list_display = ["name", "organisation", "driver", "endpoint", "credentials_source", "is_active"]
    list_filter = ["driver", "is_active", "organisation"]
    search_fields = ["name", "endpoint", "organisation__name"]
    list_select_related = ["organisation"]
    readonly_fields = ["created_at", "updated_at"]
    fieldsets = [
        (None, {"fields": ["organisation", "name", "cell", "is_active"]}),
        ("Connection", {"fields": ["driver", "endpoint", "credentials_source"]}),
        ("History", {"fields": ["created_at", "updated_at"]}),
    ]

    # The change page shows the live state and a "Test connection" button.
    change_form_template = "admin/cobots/cobot/change_form.html"

    def get_urls(self) -> list[URLPattern]:
        own = [
            path(
                "<int:pk>/state/",
                self.admin_site.admin_view(self.state_view),
                name="cobots_cobot_state",
            ),
            path(
                "<int:pk>/test-connection/",
                self.admin_site.admin_view(require_POST(self.test_connection_view)),
                name="cobots_cobot_test_connection",
            ),
        ]
        return own + super().get_urls()

    def state_view(self, request: HttpRequest, pk: int) -> HttpResponse:
        """The cobot's live state as JSON, polled by the change page."""
        cobot = self._cobot(request, pk)
        return JsonResponse(selectors.live_state(cobot))

    def test_connection_view(self, request: HttpRequest, pk: int) -> HttpResponse:
        cobot = self._cobot(request, pk)
        state = selectors.live_state(cobot)
        if state["reachable"]:
            summary = ", ".join(f"{k}: {v}" for k, v in state.items() if k != "reachable")
            self.message_user(request, f"{cobot.name} answered. {summary}", messages.SUCCESS)
        else:
            self.message_user(
                request, f"{cobot.name} did not answer: {state['error']}", messages.ERROR
            )
        return HttpResponseRedirect(reverse("admin:cobots_cobot_change", args=[cobot.pk]))

    def _cobot(self, request: HttpRequest, pk: int) -> Cobot:
        cobot = get_object_or_404(self.get_queryset(request), pk=pk)
        if not self.has_view_permission(request, cobot):
            raise PermissionDenied
        return cobot

    def get_readonly_fields(self, request: HttpRequest, obj: Cobot | None = None) -> list[str]:
        # A cobot stays in the organisation it was registered in.
        fixed = ["organisation"] if obj else []
        return [*fixed, *self.readonly_fields]

    def save_model(
        self, request: HttpRequest, obj: Cobot, form: BaseModelForm[Cobot], change: bool
    ) -> None:
        fields = {name: getattr(obj, name) for name in services.EDITABLE_FIELDS}
        if change:
            services.update_cobot(obj, **fields)
            return
        created = services.create_cobot(obj.organisation, **fields)
        obj.pk, obj._state.adding = created.pk, False

    def delete_model(self, request: HttpRequest, obj: Cobot) -> None:
        services.delete_cobot(obj)

    def delete_queryset(self, request: HttpRequest, queryset: QuerySet[Cobot]) -> None:
        for cobot in queryset:
            services.delete_cobot(cobot)


@admin.register(Device)
class DeviceAdmin(DeviceAdminBase):
    list_display = ["name", "organisation", "kind", "cell", "gateway", "is_active"]
    list_filter = ["kind", "is_active", "organisation"]
    search_fields = ["name", "cell", "organisation__name"]
    list_select_related = ["organisation", "gateway"]
    readonly_fields = ["created_at", "updated_at"]

    def save_model(
        self, request: HttpRequest, obj: Device, form: BaseModelForm[Device], change: bool
    ) -> None:
        fields = {name: getattr(obj, name) for name in services.DEVICE_FIELDS}
        if change:
            services.update_device(obj, **fields)
            return
        created = services.create_device(obj.organisation, **fields)
        obj.pk, obj._state.adding = created.pk, False
