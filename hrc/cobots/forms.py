"""The forms that register or edit a cobot or a device; hrc.cobots.services writes them.

The cell is chosen among the organisation's cells, so another organisation's
cell (or a mistyped one) is "not one of the choices" at its field.
"""

from __future__ import annotations

from typing import Any

from django import forms
from django.core.exceptions import ValidationError

from hrc.cobots.models import Cobot, Device
from hrc.organisations.selectors import cells_of


class _InACellForm(forms.ModelForm):  # type: ignore[type-arg]  # django-stubs makes it generic, Django does not
    """A cobot or a device: named once in its organisation, standing in one of its cells (or on
    the whole floor); `what` names it in the refusal of a taken name."""

    what = ""

    def __init__(self, data: Any = None, *, instance: Cobot | Device) -> None:
        super().__init__(data, instance=instance)
        names = list(cells_of(instance.organisation_id).values_list("name", flat=True))
        if instance.cell and instance.cell not in names:
            names.append(instance.cell)
        cell = self.fields["cell"]
        assert isinstance(cell, forms.ChoiceField)
        cell.choices = [("", "– the whole floor –"), *((name, name) for name in names)]

    def clean_name(self) -> str:
        name: str = self.cleaned_data["name"]
        model = type(self.instance)
        taken = model.objects.filter(organisation_id=self.instance.organisation_id, name=name)
        if taken.exclude(pk=self.instance.pk).exists():
            raise ValidationError(f"The organisation already has a {self.what} named {name}.")
        return name

    def add_service_errors(self, error: ValidationError) -> None:
        add_service_errors(self, error)


class CobotForm(_InACellForm):
    what = "cobot"
    cell = forms.ChoiceField(
        required=False,
        help_text="The cell it stands in; its tablet shows and stops it. Add cells under Organisation → Cells.",
    )

    class Meta:
        model = Cobot
        fields = ["name", "driver", "endpoint", "credentials_source", "cell", "is_active"]


class CredentialsSecretForm(forms.Form):
    """Sets a credentials secret; the password field never shows a value back."""

    name = forms.CharField(
        max_length=64,
        help_text="Cobots name it as their credentials source 'secret:NAME'. An existing name is "
        "replaced.",
    )
    username = forms.CharField(
        max_length=64, label="User name", help_text="The gateway user the driver signs in as."
    )
    password = forms.CharField(
        max_length=1024,
        strip=False,
        widget=forms.PasswordInput(render_value=False),
        help_text="Stored encrypted, never shown again.",
    )

    def add_service_errors(self, error: ValidationError) -> None:
        for field, messages in error.message_dict.items():
            self.add_error(field if field in self.fields else None, messages)


class DeviceForm(_InACellForm):
    """Registers or edits a device: its cell among the organisation's, its gateway among the
    organisation's cobots (another's is "not one of the choices")."""

    what = "device"

    cell = forms.ChoiceField(
        required=False,
        help_text="The cell it stands in: that cell's cobots call it, and the cell's STOP holds it.",
    )

    class Meta:
        model = Device
        fields = ["name", "kind", "cell", "gateway", "is_active"]

    def __init__(self, data: Any = None, *, instance: Device) -> None:
        super().__init__(data, instance=instance)
        gateway = self.fields["gateway"]
        assert isinstance(gateway, forms.ModelChoiceField)
        gateway.queryset = Cobot.objects.filter(organisation_id=instance.organisation_id)


def add_service_errors(form: forms.BaseForm, error: ValidationError) -> None:
    """Puts a service's refusal at its field (or above the form when it names none)."""
    if hasattr(error, "error_dict"):
        for field, messages in error.message_dict.items():
            form.add_error(field if field in form.fields else None, messages)
    else:
        form.add_error(None, error.messages)
