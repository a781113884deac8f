"""Admin pages for patterns (drafts editable) and published versions (read-only).

Saves go through hrc.patterns.services; the draft field's validator has
already refused a document that is not `hrc-pattern/1` in shape.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from django.contrib import admin
from django.db.models import Count, Max, QuerySet
from django.forms import BaseModelForm
from django.http import HttpRequest

from hrc.patterns import services
from hrc.patterns.models import PatternModel, PatternVersion

# Generic for mypy only: Django's runtime classes are not subscriptable.
if TYPE_CHECKING:
    VersionInlineBase = admin.TabularInline[PatternVersion, PatternModel]
    PatternAdminBase = admin.ModelAdmin[PatternModel]
    VersionAdminBase = admin.ModelAdmin[PatternVersion]
else:
    VersionInlineBase = admin.TabularInline
    PatternAdminBase = VersionAdminBase = admin.ModelAdmin


class PatternVersionInline(VersionInlineBase):
    model = PatternVersion
    fields = readonly_fields = ("number", "published_by", "published_at")
    extra = 0
    can_delete = False
    show_change_link = True

    def has_add_permission(self, request: HttpRequest, obj: PatternModel | None = None) -> bool:
        return False  # versions are made by publishing, which checks the draft first

    def has_change_permission(self, request: HttpRequest, obj: PatternModel | None = None) -> bool:
        return False


@admin.register(PatternModel)
class PatternModelAdmin(PatternAdminBase):
    list_display = ["name", "organisation", "latest_version", "created_by", "updated_at"]
    list_filter = ["organisation", "created_at", "updated_at"]
    search_fields = ["name", "description", "organisation__name"]
    list_select_related = ["organisation", "created_by"]
    readonly_fields = ["created_by", "created_at", "updated_at"]
    fields = ["organisation", "name", "description", "draft", *readonly_fields]
    inlines = [PatternVersionInline]

    def get_queryset(self, request: HttpRequest) -> QuerySet[PatternModel]:
        return (
            super()
            .get_queryset(request)
            .annotate(last_number=Max("versions__number"), version_total=Count("versions"))
        )

    @admin.display(description="Latest version", ordering="last_number")
    def latest_version(self, pattern: PatternModel) -> str:
        number = getattr(pattern, "last_number", None)
        return f"v{number}" if number else "not published"

    def get_readonly_fields(
        self, request: HttpRequest, obj: PatternModel | None = None
    ) -> list[str]:
        fixed = ["organisation"] if obj else []
        return [*fixed, *self.readonly_fields]

    def save_model(
        self,
        request: HttpRequest,
        obj: PatternModel,
        form: BaseModelForm[PatternModel],
        change: bool,
    ) -> None:
        if change:
            services.update_pattern(
                obj, name=obj.name, description=obj.description, draft=obj.draft
            )
            return
        created = services.create_pattern(
            obj.organisation,
            name=obj.name,
            description=obj.description,
            draft=obj.draft,
            created_by=request.user if request.user.is_authenticated else None,
        )
        obj.pk, obj._state.adding = created.pk, False

    def has_delete_permission(self, request: HttpRequest, obj: PatternModel | None = None) -> bool:
        # Published patterns are kept: their versions are the record cases run against.
        if obj is not None and obj.versions.exists():
            return False
        return super().has_delete_permission(request, obj)

    def delete_model(self, request: HttpRequest, obj: PatternModel) -> None:
        services.delete_pattern(obj)

    def delete_queryset(self, request: HttpRequest, queryset: QuerySet[PatternModel]) -> None:
        for pattern in queryset:
            services.delete_pattern(pattern)


@admin.register(PatternVersion)
class PatternVersionAdmin(VersionAdminBase):
    """Published versions are immutable: this page shows them and offers no change."""

    list_display = ["pattern", "number", "organisation", "published_by", "published_at"]
    list_filter = ["pattern__organisation", "published_at"]
    search_fields = ["pattern__name", "published_by__username"]
    list_select_related = ["pattern__organisation", "published_by"]
    fields = readonly_fields = (
        "pattern",
        "number",
        "published_by",
        "published_at",
        "document",
        "report",
    )

    @admin.display(description="Organisation", ordering="pattern__organisation__name")
    def organisation(self, version: PatternVersion) -> str:
        return str(version.pattern.organisation)

    def has_add_permission(self, request: HttpRequest) -> bool:
        return False

    def has_change_permission(
        self, request: HttpRequest, obj: PatternVersion | None = None
    ) -> bool:
        return False

    def has_delete_permission(
        self, request: HttpRequest, obj: PatternVersion | None = None
    ) -> bool:
        return False
