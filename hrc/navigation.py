"""Where a signed-in person is: the organisation they are working in.

People in several organisations pick one (the header's switcher stores it in
the session); everyone else is simply in their only one. Pages that act on
"the organisation" (administration, starting a case) use this.
"""

from django.http import HttpRequest

from hrc.organisations.models import Membership
from hrc.organisations.selectors import memberships_of

SESSION_KEY = "hrc.organisation"


def current_membership(request: HttpRequest) -> Membership | None:
    """The membership of the organisation the person chose, else their first; None for outsiders."""
    memberships = memberships_of(request.user).order_by("organisation__name")
    chosen = request.session.get(SESSION_KEY)
    if chosen is not None:
        membership = memberships.filter(organisation_id=chosen).first()
        if membership is not None:
            return membership
    return memberships.first()
