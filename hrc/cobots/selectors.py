"""Reads of cobots across the organisation wall."""

from django.db.models import QuerySet

from hrc.cobots.models import Cobot
from hrc.organisations.selectors import AnyUser, organisations_of


def cobots_visible_to(user: AnyUser) -> QuerySet[Cobot]:
    """The cobots of every organisation the user belongs to; none for an outsider."""
    return Cobot.objects.filter(organisation__in=organisations_of(user)).select_related(
        "organisation"
    )
