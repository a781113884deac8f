"""Admin pages for cobots; saves go through hrc.cobots.services."""

from __future__ import annotations

from typing import TYPE_CHECKING

from django.contrib import admin
from django.db.models import QuerySet
from django.forms import BaseModelForm
from django.http import HttpRequest

from hrc.cobots import services
from hrc.cobots.models import Cobot

# Generic for mypy only: Django's runtime class is not subscriptable.
if TYPE_CHECKING:
    CobotAdminBase = admin.ModelAdmin[Cobot]
else:
    CobotAdminBase = admin.ModelAdmin


@admin.register(Cobot)
class CobotAdmin(CobotAdminBase):
    list_display = ["name", "organisation", "driver", "endpoint", "credentials_source", "is_active"]
    list_filter = ["driver", "is_active", "organisation"]
    search_fields = ["name", "endpoint", "organisation__name"]
    list_select_related = ["organisation"]
    readonly_fields = ["created_at", "updated_at"]
    fieldsets = [
        (None, {"fields": ["organisation", "name", "is_active"]}),
        ("Connection", {"fields": ["driver", "endpoint", "credentials_source"]}),
        ("History", {"fields": ["created_at", "updated_at"]}),
    ]

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
