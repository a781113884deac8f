"""What the organisations app asks of the apps above it, through functions they register.

Imports point inwards: cases imports organisations, never the other way. Yet
when an admin deactivates a person, the tasks that person holds must go back
to their team, and only the cases app knows them; before a cell is deleted,
only the cobots app knows who stands in it; when a membership ends, only the
live app knows the person's open sockets. Each registers its answer in its
receivers.py (hrc.cases, hrc.cobots, hrc.live), which its AppConfig.ready() loads; nothing
registered means nothing held and nobody standing there.
"""

from __future__ import annotations

from collections.abc import Callable

from django.contrib.auth.models import User

# Gives back every open task `user` holds in the organisation (id), recorded as done by `by`;
# returns how many went back.
HandBack = Callable[[User, int, User | None], int]

# Tells the user's (id) open connections that their membership of the organisation (id) ended.
MembershipEnded = Callable[[int, int], None]

# The names of the cobots standing in the organisation's (id) cell of that name.
Occupants = Callable[[int, str], list[str]]

_HAND_BACK: list[HandBack] = []
_OCCUPANTS: list[Occupants] = []
_ENDED: list[MembershipEnded] = []


def register_member_leaving(hand_back: HandBack) -> None:
    """Called once by the app that runs cases, from its receivers.py."""
    if hand_back not in _HAND_BACK:
        _HAND_BACK.append(hand_back)


def hand_back_work(user: User, organisation_id: int, by: User | None) -> int:
    """Asks every registered app to give back what `user` holds; the number of tasks given back."""
    return sum(hand_back(user, organisation_id, by) for hand_back in _HAND_BACK)


def register_cell_occupants(occupants: Occupants) -> None:
    """Called once by the app that places things in cells, from its receivers.py."""
    if occupants not in _OCCUPANTS:
        _OCCUPANTS.append(occupants)


def cell_occupants(organisation_id: int, cell: str) -> list[str]:
    """Every registered app's names of what stands in the cell, sorted."""
    return sorted(name for occupants in _OCCUPANTS for name in occupants(organisation_id, cell))


def register_membership_ended(ended: MembershipEnded) -> None:
    """Called once by the app that holds people's live connections, from its receivers.py."""
    if ended not in _ENDED:
        _ENDED.append(ended)


def membership_ended(user_id: int, organisation_id: int) -> None:
    """Tells every registered app that the user is no longer a member of the organisation."""
    for ended in _ENDED:
        ended(user_id, organisation_id)
