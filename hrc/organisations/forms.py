"""The administration's forms: they read and check the input; the services write.

Choices (teams, members) are limited to the admin's organisation, so another
organisation's id is "not one of the choices" at its field.
"""

from __future__ import annotations

from typing import Any

from django import forms
from django.core.exceptions import ValidationError

from hrc.organisations.choices import Role
from hrc.organisations.models import Membership, Organisation, Team
from hrc.organisations.validators import validate_cell


class MemberChoices(forms.ModelMultipleChoiceField):  # type: ignore[type-arg]  # generic in django-stubs only
    """Members shown by their username."""

    def label_from_instance(self, obj: Any) -> str:
        return str(obj.user.get_username())


class _OrganisationForm(forms.Form):
    def __init__(self, organisation: Organisation, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.organisation = organisation
        teams = self.fields.get("teams")
        if isinstance(teams, forms.ModelMultipleChoiceField):
            teams.queryset = Team.objects.filter(organisation=organisation).order_by("name")
        members = self.fields.get("members")
        if isinstance(members, forms.ModelMultipleChoiceField):
            members.queryset = (
                Membership.objects.filter(organisation=organisation, is_active=True)
                .select_related("user")
                .order_by("user__username")
            )

    def add_service_errors(self, error: ValidationError) -> None:
        """Puts a service's refusal at its field (or above the form when it names none)."""
        if hasattr(error, "error_dict"):
            for field, messages in error.message_dict.items():
                self.add_error(field if field in self.fields else None, messages)
        else:
            self.add_error(None, error.messages)


class TeamChoices(forms.ModelMultipleChoiceField):  # type: ignore[type-arg]  # generic in django-stubs only
    """Teams shown by their name (all are the admin's organisation's)."""

    def label_from_instance(self, obj: Any) -> str:
        return str(obj.name)


class PersonForm(_OrganisationForm):
    username = forms.CharField(max_length=150, help_text="What they type to sign in.")
    name = forms.CharField(max_length=150, required=False, help_text="First and last name.")
    email = forms.EmailField(required=False, label="E-mail")
    role = forms.ChoiceField(choices=Role.choices, initial=Role.OPERATOR)
    teams = TeamChoices(
        queryset=Team.objects.none(), required=False, widget=forms.CheckboxSelectMultiple
    )
    invite = forms.BooleanField(
        required=False,
        label="Invitation link",
        help_text="Instead of a password: a link, valid once and for a few days, where they choose their own.",
    )


class MemberForm(_OrganisationForm):
    role = forms.ChoiceField(choices=Role.choices)
    teams = TeamChoices(
        queryset=Team.objects.none(), required=False, widget=forms.CheckboxSelectMultiple
    )


class TeamForm(_OrganisationForm):
    name = forms.CharField(max_length=200)
    members = MemberChoices(
        queryset=Membership.objects.none(), required=False, widget=forms.CheckboxSelectMultiple
    )


class CellForm(_OrganisationForm):
    name = forms.CharField(
        max_length=50,
        validators=[validate_cell],
        help_text="Letters, digits, - and _: it is part of the tablet's address.",
    )
    description = forms.CharField(max_length=300, required=False)


class CellDescriptionForm(_OrganisationForm):
    description = forms.CharField(max_length=300, required=False)
