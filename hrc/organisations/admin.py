"""Admin pages for organisations, memberships and teams.

Saves go through hrc.organisations.services like every other write; the
forms have already run the model's validation by the time save_model runs.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from django import forms
from django.contrib import admin
from django.db.models import Count, QuerySet
from django.forms import BaseModelForm
from django.forms.models import BaseInlineFormSet
from django.http import HttpRequest

from hrc.organisations import services
from hrc.organisations.models import AdminRecord, Membership, Organisation, Team

# django-stubs types these classes as generics, Django's runtime classes are not
# subscriptable (without the django-stubs-ext runtime patch, which is a dev-only package).
if TYPE_CHECKING:
    MembershipFormBase = forms.ModelForm[Membership]
    TeamFormBase = forms.ModelForm[Team]
    MembershipInlineBase = admin.TabularInline[Membership, Organisation]
    OrganisationAdminBase = admin.ModelAdmin[Organisation]
    MembershipAdminBase = admin.ModelAdmin[Membership]
    TeamAdminBase = admin.ModelAdmin[Team]
    AdminRecordAdminBase = admin.ModelAdmin[AdminRecord]
else:
    MembershipFormBase = TeamFormBase = forms.ModelForm
    MembershipInlineBase = admin.TabularInline
    OrganisationAdminBase = MembershipAdminBase = TeamAdminBase = admin.ModelAdmin
    AdminRecordAdminBase = admin.ModelAdmin


class MembershipInlineForm(MembershipFormBase):
    """Once a membership exists only its role changes: a new person gets a new row."""

    class Meta:
        model = Membership
        fields = ["user", "role"]

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        if self.instance.pk is not None:
            self.fields["user"].disabled = True


class MembershipInline(MembershipInlineBase):
    model = Membership
    form = MembershipInlineForm
    extra = 1
    autocomplete_fields = ["user"]
    fields = ["user", "role", "joined_at"]
    readonly_fields = ["joined_at"]


@admin.register(Organisation)
class OrganisationAdmin(OrganisationAdminBase):
    list_display = ["name", "slug", "member_count", "created_at"]
    search_fields = ["name", "slug"]
    prepopulated_fields = {"slug": ("name",)}
    readonly_fields = ["created_at"]
    inlines = [MembershipInline]

    def get_queryset(self, request: HttpRequest) -> QuerySet[Organisation]:
        return super().get_queryset(request).annotate(member_total=Count("memberships"))

    @admin.display(description="Members", ordering="member_total")
    def member_count(self, organisation: Organisation) -> int:
        return int(getattr(organisation, "member_total", 0))

    def save_model(
        self,
        request: HttpRequest,
        obj: Organisation,
        form: BaseModelForm[Organisation],
        change: bool,
    ) -> None:
        if change:
            services.update_organisation(obj, name=obj.name, slug=obj.slug)
            return
        created = services.create_organisation(name=obj.name, slug=obj.slug)
        obj.pk, obj._state.adding = created.pk, False

    def save_formset(
        self,
        request: HttpRequest,
        form: BaseModelForm[Organisation],
        formset: BaseInlineFormSet[Membership, Organisation, Any],
        change: bool,
    ) -> None:
        memberships = formset.save(commit=False)
        for membership in formset.deleted_objects:
            services.remove_member(membership)
        for membership in memberships:
            if membership.pk is None:
                services.add_member(form.instance, membership.user, membership.role)
            else:
                services.change_role(membership, membership.role)

    def delete_model(self, request: HttpRequest, obj: Organisation) -> None:
        services.delete_organisation(obj)

    def delete_queryset(self, request: HttpRequest, queryset: QuerySet[Organisation]) -> None:
        for organisation in queryset:
            services.delete_organisation(organisation)


@admin.register(Membership)
class MembershipAdmin(MembershipAdminBase):
    list_display = ["user", "organisation", "role", "is_active", "joined_at"]
    list_filter = ["role", "is_active", "organisation"]
    search_fields = ["user__username", "user__email", "organisation__name"]
    autocomplete_fields = ["user", "organisation"]
    list_select_related = ["user", "organisation"]

    def get_readonly_fields(self, request: HttpRequest, obj: Membership | None = None) -> list[str]:
        # A membership is one person in one organisation; moving it would be a different one.
        # Deactivating hands the person's tasks back: the organisation's people page does it.
        if obj:
            return ["user", "organisation", "is_active", "joined_at"]
        return ["is_active", "joined_at"]

    def save_model(
        self, request: HttpRequest, obj: Membership, form: BaseModelForm[Membership], change: bool
    ) -> None:
        if change:
            services.change_role(obj, obj.role)
            return
        created = services.add_member(obj.organisation, obj.user, obj.role)
        obj.pk, obj._state.adding = created.pk, False

    def delete_model(self, request: HttpRequest, obj: Membership) -> None:
        services.remove_member(obj)

    def delete_queryset(self, request: HttpRequest, queryset: QuerySet[Membership]) -> None:
        for membership in queryset:
            services.remove_member(membership)


class TeamAdminForm(TeamFormBase):
    class Meta:
        model = Team
        fields = ["organisation", "name", "members"]

    def clean(self) -> dict[str, Any] | None:
        cleaned = super().clean() or {}
        # On change the organisation is read-only, so it is not in the cleaned data.
        organisation = cleaned.get("organisation") or (
            self.instance.organisation if self.instance.pk else None
        )
        strangers = [
            m
            for m in cleaned.get("members", [])
            if m.organisation_id != getattr(organisation, "pk", None)
        ]
        if organisation and strangers:
            names = ", ".join(str(m.user) for m in strangers)
            self.add_error(
                "members", f"Only members of {organisation} can join its teams, not {names}."
            )
        return cleaned


@admin.register(Team)
class TeamAdmin(TeamAdminBase):
    form = TeamAdminForm
    list_display = ["name", "organisation", "size"]
    list_filter = ["organisation"]
    search_fields = ["name", "organisation__name", "members__user__username"]
    filter_horizontal = ["members"]
    list_select_related = ["organisation"]

    def get_queryset(self, request: HttpRequest) -> QuerySet[Team]:
        return super().get_queryset(request).annotate(member_total=Count("members"))

    @admin.display(description="Members", ordering="member_total")
    def size(self, team: Team) -> int:
        return int(getattr(team, "member_total", 0))

    def get_readonly_fields(self, request: HttpRequest, obj: Team | None = None) -> list[str]:
        return ["organisation"] if obj else []

    def save_model(
        self, request: HttpRequest, obj: Team, form: BaseModelForm[Team], change: bool
    ) -> None:
        if change:
            services.rename_team(obj, name=obj.name)
            return
        created = services.create_team(obj.organisation, name=obj.name)
        obj.pk, obj._state.adding = created.pk, False

    def save_related(
        self, request: HttpRequest, form: BaseModelForm[Team], formsets: Any, change: bool
    ) -> None:
        services.set_team_members(form.instance, form.cleaned_data.get("members", []))

    def delete_model(self, request: HttpRequest, obj: Team) -> None:
        services.delete_team(obj)

    def delete_queryset(self, request: HttpRequest, queryset: QuerySet[Team]) -> None:
        for team in queryset:
            services.delete_team(team)


@admin.register(AdminRecord)
class AdminRecordAdmin(AdminRecordAdminBase):
    """The organisations' administration records, read only: they are what happened."""

    list_display = ["at", "organisation", "actor", "action", "target"]
    list_filter = ["action", "organisation"]
    search_fields = ["target", "actor__username"]
    list_select_related = ["organisation", "actor"]

    def has_add_permission(self, request: HttpRequest) -> bool:
        return False

    def has_change_permission(self, request: HttpRequest, obj: AdminRecord | None = None) -> bool:
        return False

    def has_delete_permission(self, request: HttpRequest, obj: AdminRecord | None = None) -> bool:
        return False


def _superusers_only(request: HttpRequest) -> bool:
    # The site shows every organisation at once, so it is for the people who run the
    # installation. An organisation's admins administer it at /organisation/, inside its wall.
    return bool(request.user.is_active and request.user.is_superuser)


admin.site.has_permission = _superusers_only  # type: ignore[method-assign]
