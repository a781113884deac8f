"""The pages' forms for running a version: who performs each actor, and what a case starts with.

The forms only turn what a person chose into the services' input (an actor
mapping, start data); the services check it (hrc.cases.mapping, start_cases)
and a refusal comes back to the fields it names (`Invalid.fields`).
"""

import json
from collections.abc import Mapping
from typing import Any

from django import forms
from django.contrib.auth.models import User

from hrc.cases.services import MAX_CASES_AT_ONCE
from hrc.cobots.models import Cobot, Device
from hrc.engine.model import Pattern
from hrc.engine.startdata import StartField, start_fields
from hrc.engine.taskconfig import device_kind_of
from hrc.errors import Invalid
from hrc.organisations.models import Organisation, Team

YES_NO = [("", "Choose…"), ("yes", "Yes"), ("no", "No")]


def actor_field_name(actor: str) -> str:
    return f"actor__{actor}"


def data_field_name(key: str) -> str:
    return f"data__{key}"


class MappingForm(forms.Form):
    """One choice per pattern actor: a team or a person for operators, a cobot for cobots, a
    device of its kind for a device actor."""

    def __init__(
        self,
        *args: Any,
        pattern: Pattern,
        organisation: Organisation,
        defaults: Mapping[str, Any],
        **kwargs: Any,
    ) -> None:
        super().__init__(*args, **kwargs)
        self.pattern = pattern
        teams = list(Team.objects.filter(organisation=organisation).order_by("name"))
        people = list(
            User.objects.filter(
                memberships__organisation=organisation, memberships__is_active=True, is_active=True
            )
            .order_by("username")
            .distinct()
        )
        cobots = list(
            Cobot.objects.filter(organisation=organisation, is_active=True).order_by("name")
        )
        devices = list(
            Device.objects.filter(organisation=organisation, is_active=True).order_by("name")
        )
        for actor in pattern.actors:
            kind = device_kind_of(actor)
            if kind is not None:
                choices = [
                    (f"device:{d.pk}", f"{d.name}{f' (cell {d.cell})' if d.cell else ''}")
                    for d in devices
                    if d.kind == kind
                ]
            elif actor.type == "cobot":
                choices = [
                    (f"cobot:{c.pk}", f"{c.name}{f' (cell {c.cell})' if c.cell else ''}")
                    for c in cobots
                ]
            else:
                choices = [(f"team:{t.pk}", f"Team {t.name}") for t in teams]
                choices += [(f"users:{u.pk}", f"{u.get_full_name() or u.username}") for u in people]
            initial = _choice_of(defaults.get(actor.id))
            if initial and initial not in {value for value, _ in choices}:
                # A default of several people has no single choice: it is offered as it is.
                choices.append((initial, "the version's default"))
            self.fields[actor_field_name(actor.id)] = forms.ChoiceField(
                label=f"{actor.extra.get('name') or actor.id} ({actor.type})",
                choices=[("", "Choose…"), *choices],
                initial=initial,
            )

    def mapping(self) -> dict[str, dict[str, Any]]:
        """The chosen performers as an actor mapping (ids), for the services to check."""
        chosen: dict[str, dict[str, Any]] = {}
        for actor in self.pattern.actors:
            value = self.cleaned_data.get(actor_field_name(actor.id), "")
            kind, _, ids = value.partition(":")
            if kind == "users":
                chosen[actor.id] = {
                    "users": [int(i) for i in ids.split(",") if i.isascii() and i.isdigit()]
                }
            elif kind in ("team", "cobot", "device") and ids.isascii() and ids.isdigit():
                chosen[actor.id] = {kind: int(ids)}
        return chosen

    def refuse(self, invalid: Invalid) -> None:
        refuse(self, invalid)


class CycleForm(forms.Form):
    """What one start of a version says: a reference and the start data (an operator's start at
    their cell's tablet, with the version's mapping)."""

    reference = forms.CharField(
        required=False,
        max_length=100,
        help_text="What the case works on: an order or workpiece number.",
    )

    def __init__(self, *args: Any, data_defaults: Mapping[str, Any], **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.start_fields = start_fields(data_defaults)
        for field in self.start_fields:
            self.fields[data_field_name(field.key)] = data_form_field(field)

    def start_data(self) -> dict[str, Any]:
        """The data keys whose answer differs from the pattern's default (only what was changed)."""
        data = {}
        for field in self.start_fields:
            value = self.cleaned_data.get(data_field_name(field.key))
            if value != field.default:
                data[field.key] = value
        return data

    def refuse(self, invalid: Invalid) -> None:
        refuse(self, invalid)


class StartForm(CycleForm):
    """A case's start by an engineer or admin: the mapping (the version's defaults, overridable
    for these cases), the start data, a reference and how many cases alike to start."""

    count = forms.IntegerField(
        min_value=1,
        max_value=MAX_CASES_AT_ONCE,
        initial=1,
        help_text=f"How many cases alike to start (at most {MAX_CASES_AT_ONCE}).",
    )

    def __init__(
        self,
        *args: Any,
        pattern: Pattern,
        organisation: Organisation,
        defaults: Mapping[str, Any],
        data_defaults: Mapping[str, Any],
        **kwargs: Any,
    ) -> None:
        super().__init__(*args, data_defaults=data_defaults, **kwargs)
        self.performers = MappingForm(
            *args, pattern=pattern, organisation=organisation, defaults=defaults, **kwargs
        )
        self.fields.update(self.performers.fields)

    def mapping(self) -> dict[str, dict[str, Any]]:
        self.performers.cleaned_data = self.cleaned_data
        return self.performers.mapping()


def refuse(form: forms.Form, invalid: Invalid) -> None:
    """Shows the services' refusal at the fields it names (data.batch → data__batch), else above."""
    shown = False
    for name, messages in invalid.fields.items():
        field = name.replace("actor_mapping.", "actor__").replace(".", "__")
        if field in form.fields:
            form.add_error(field, messages)
            shown = True
    if not shown:
        form.add_error(None, str(invalid))


def data_form_field(field: StartField) -> forms.Field:
    """The form field for one key of the pattern's data, typed by its default."""
    label = field.title
    if field.kind == "boolean":
        return YesNoField(label=label, initial="yes" if field.default else "no")
    if field.kind == "integer":
        return forms.IntegerField(label=label, initial=field.default)
    if field.kind == "number":
        return forms.FloatField(label=label, initial=field.default)
    if field.kind == "text":
        return forms.CharField(label=label, initial=field.default, required=False)
    return JsonField(label=label, initial=json.dumps(field.default), default=field.default)


class YesNoField(forms.ChoiceField):
    """Yes or no, both shown, neither taken for granted."""

    def __init__(self, **kwargs: Any) -> None:
        super().__init__(choices=YES_NO, **kwargs)

    def clean(self, value: Any) -> bool:
        return bool(super().clean(value) == "yes")


class JsonField(forms.CharField):
    """A list or an object, written as JSON; it must stay the kind its default is."""

    widget = forms.Textarea(attrs={"rows": 3})

    def __init__(self, *, default: Any, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.default = default

    def clean(self, value: Any) -> Any:
        text = super().clean(value)
        try:
            parsed = json.loads(text)
        except json.JSONDecodeError as error:
            raise forms.ValidationError(
                f"This is not JSON: {error.msg} (line {error.lineno})."
            ) from None
        if isinstance(self.default, list) and not isinstance(parsed, list):
            raise forms.ValidationError("Give a list, as the default is: [ … ].")
        if isinstance(self.default, dict) and not isinstance(parsed, dict):
            raise forms.ValidationError("Give an object, as the default is: { … }.")
        return parsed


class StartRightsForm(forms.Form):
    """Who may start a version's cases: roles, and the cells whose tablets offer it to operators."""

    roles = forms.MultipleChoiceField(
        required=False, widget=forms.CheckboxSelectMultiple, label="Roles that may start it"
    )
    cells = forms.MultipleChoiceField(
        required=False,
        widget=forms.CheckboxSelectMultiple,
        label="Cells whose tablets offer it to operators",
    )

    def __init__(
        self, *args: Any, roles: list[tuple[str, str]], cells: list[str], **kwargs: Any
    ) -> None:
        super().__init__(*args, **kwargs)
        self.fields["roles"].choices = roles  # type: ignore[attr-defined]
        self.fields["cells"].choices = [(cell, cell) for cell in cells]  # type: ignore[attr-defined]


def _choice_of(binding: Any) -> str:
    """The form's value for a stored mapping of one actor: team:3, users:4,5 or cobot:2."""
    if not isinstance(binding, Mapping):
        return ""
    if "cobot" in binding:
        return f"cobot:{binding['cobot']}"
    if "device" in binding:
        return f"device:{binding['device']}"
    if "team" in binding:
        return f"team:{binding['team']}"
    users = binding.get("users") or []
    return "users:" + ",".join(str(u) for u in users) if users else ""
