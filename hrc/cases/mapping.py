"""Actor mappings: who performs each pattern actor in a case.

`{"o": {"users": [3, "anna"]}, "o2": {"team": "Shift A"}, "c": {"cobot": "cobot1"},
"axis": {"device": "axis1"}}` (ids or names). Operators map to users or a team of the
organisation, cobots to an active cobot of it, device actors to an active device of their
kind (by default the organisation's only one). Stored with ids only.

A device call in a cobot's lane runs on the device of its kind in the mapped cobot's cell,
resolved here too (`{"cobot": 4, "devices": {"display": 9}}`): a case never starts with a
call no device can serve.
"""

from collections.abc import Mapping
from typing import Any

from django.contrib.auth import get_user_model

from hrc.cobots.models import Cobot, Device
from hrc.engine.model import Actor, Pattern
from hrc.engine.taskconfig import device_kind_of, device_kinds_called
from hrc.errors import Invalid
from hrc.organisations.models import Organisation, Team


def resolve_actor_mapping(
    pattern: Pattern, organisation: Organisation, mapping: Mapping[str, Any]
) -> dict[str, dict[str, Any]]:
    """The mapping with names turned into ids, checked against the organisation.

    Raises Invalid naming the actor.
    """
    unknown = sorted(set(mapping) - {a.id for a in pattern.actors})
    if unknown:
        raise Invalid.at("actor_mapping", f"The pattern has no actor {', '.join(unknown)}.")
    resolved: dict[str, dict[str, Any]] = {}
    calls = device_kinds_called(pattern)
    for actor in pattern.actors:
        binding = mapping.get(actor.id)
        kind = device_kind_of(actor)
        if kind is not None:
            resolved[actor.id] = {"device": _device(actor, kind, organisation, binding)}
            continue
        if not isinstance(binding, Mapping) or not binding:
            raise Invalid.at(
                f"actor_mapping.{actor.id}",
                f"Actor {actor.id} ({actor.type}) is not mapped: give "
                + (
                    "{'cobot': id or name}."
                    if actor.type == "cobot"
                    else "{'users': [...]} or {'team': id or name}."
                ),
            )
        if actor.type == "cobot":
            cobot = _cobot(actor.id, organisation, binding)
            resolved[actor.id] = {"cobot": cobot.pk}
            if actor.id in calls:
                resolved[actor.id]["devices"] = _cell_devices(actor.id, cobot, calls[actor.id])
        elif "team" in binding:
            resolved[actor.id] = {"team": _team(actor.id, organisation, binding["team"])}
        else:
            resolved[actor.id] = {"users": _users(actor.id, organisation, binding.get("users"))}
    return resolved


def _cobot(actor: str, organisation: Organisation, binding: Mapping[str, Any]) -> Cobot:
    reference = binding.get("cobot")
    cobots = Cobot.objects.filter(organisation=organisation, is_active=True)
    cobot = _by_id_or_name(cobots, reference, "name")
    if cobot is None:
        raise Invalid.at(
            f"actor_mapping.{actor}",
            f"Actor {actor}: the organisation has no active cobot {reference!r}.",
        )
    return cobot  # type: ignore[no-any-return]


def _device(actor: Actor, kind: str, organisation: Organisation, binding: Any) -> int:
    """The device a device actor maps to: the one named, else the organisation's only one."""
    devices = Device.objects.filter(organisation=organisation, kind=kind, is_active=True)
    field = f"actor_mapping.{actor.id}"
    if isinstance(binding, Mapping) and binding:
        device = _by_id_or_name(devices, binding.get("device"), "name")
        if device is None:
            raise Invalid.at(
                field,
                f"Actor {actor.id}: the organisation has no active {kind} device "
                f"{binding.get('device')!r}.",
            )
        return int(device.pk)
    found = list(devices.values_list("pk", flat=True)[:2])
    if len(found) != 1:
        why = "none" if not found else "several"
        raise Invalid.at(
            field,
            f"Actor {actor.id} is a {kind} device and the organisation has {why} active: give "
            "{'device': id or name}"
            + (", after registering one under Cobots → Devices." if not found else "."),
        )
    return int(found[0])


def _cell_devices(actor: str, cobot: Cobot, kinds: set[str]) -> dict[str, int]:
    """The device of each kind the actor's lane calls, in its cobot's cell: exactly one each."""
    resolved = {}
    for kind in sorted(kinds):
        found = list(
            Device.objects.filter(
                organisation_id=cobot.organisation_id, cell=cobot.cell, kind=kind, is_active=True
            ).values_list("pk", flat=True)[:2]
        )
        if len(found) != 1:
            cell = f"cell {cobot.cell}" if cobot.cell else "the floor (no cell)"
            why = "no active" if not found else "more than one active"
            raise Invalid.at(
                f"actor_mapping.{actor}",
                f"Actor {actor} calls a {kind} device, and {cobot.name}'s {cell} has {why} "
                f"{kind} device: " + (
                    f"register one in {cell} under Cobots → Devices."
                    if not found
                    else "deactivate all but one, or move them to other cells."
                ),
            )  # fmt: skip
        resolved[kind] = int(found[0])
    return resolved


def _team(actor: str, organisation: Organisation, reference: Any) -> int:
    team = _by_id_or_name(Team.objects.filter(organisation=organisation), reference, "name")
    if team is None:
        raise Invalid.at(
            f"actor_mapping.{actor}",
            f"Actor {actor}: the organisation has no team {reference!r}.",
        )
    return int(team.pk)


def _users(actor: str, organisation: Organisation, references: Any) -> list[int]:
    if not isinstance(references, list) or not references:
        raise Invalid.at(
            f"actor_mapping.{actor}",
            f"Actor {actor}: 'users' must be a non-empty list of user ids or names.",
        )
    # A deactivated person signs in nowhere: a task offered to them would wait forever.
    members = get_user_model().objects.filter(
        memberships__organisation=organisation, memberships__is_active=True, is_active=True
    )
    ids = []
    for reference in references:
        user = _by_id_or_name(members, reference, "username")
        if user is None:
            raise Invalid.at(
                f"actor_mapping.{actor}",
                f"Actor {actor}: {reference!r} is not an active member of the organisation.",
            )
        ids.append(int(user.pk))
    return sorted(set(ids))


def _by_id_or_name(queryset: Any, reference: Any, name_field: str) -> Any:
    if isinstance(reference, bool):
        return None
    if isinstance(reference, int):
        return queryset.filter(pk=reference).first()
    if isinstance(reference, str) and reference:
        return queryset.filter(**{name_field: reference}).first()
    return None
