"""Actor mappings: who performs each pattern actor in a case.

`{"o": {"users": [3, "anna"]}, "o2": {"team": "Shift A"}, "c": {"cobot": "cobot1"}}`
(ids or names). Operators map to users or a team of the organisation,
cobots to an active cobot of it. Stored with ids only.
"""

from collections.abc import Mapping
from typing import Any

from django.contrib.auth import get_user_model

from hrc.cobots.models import Cobot
from hrc.engine.model import Pattern
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
    for actor in pattern.actors:
        binding = mapping.get(actor.id)
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
            resolved[actor.id] = {"cobot": _cobot(actor.id, organisation, binding)}
        elif "team" in binding:
            resolved[actor.id] = {"team": _team(actor.id, organisation, binding["team"])}
        else:
            resolved[actor.id] = {"users": _users(actor.id, organisation, binding.get("users"))}
    return resolved


def _cobot(actor: str, organisation: Organisation, binding: Mapping[str, Any]) -> int:
    reference = binding.get("cobot")
    cobots = Cobot.objects.filter(organisation=organisation, is_active=True)
    cobot = _by_id_or_name(cobots, reference, "name")
    if cobot is None:
        raise Invalid.at(
            f"actor_mapping.{actor}",
            f"Actor {actor}: the organisation has no active cobot {reference!r}.",
        )
    return int(cobot.pk)


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
