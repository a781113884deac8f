"""The live app's answers to the inner apps' hooks, registered when Django is ready (apps.py)."""

from hrc.cases import events as case_events
from hrc.live import broadcast
from hrc.organisations import hooks as organisation_hooks

# An admin who ends a membership closes that person's sockets at once.
organisation_hooks.register_membership_ended(broadcast.membership_ended_on_commit)
# What cases record reaches the tablets after commit.
case_events.register_publisher(
    case_event=broadcast.case_event_on_commit,
    cobot_queue=broadcast.cobot_queue_on_commit,
    hold=broadcast.hold,
)
