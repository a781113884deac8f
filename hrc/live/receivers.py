"""The live app's answers to the inner apps' hooks, registered when Django is ready (apps.py)."""

from hrc.cases import events as case_events
from hrc.cobots import hooks as cobot_hooks
from hrc.live import groups
from hrc.organisations import hooks as organisation_hooks

# An admin who ends a membership closes that person's sockets at once.
organisation_hooks.register_membership_ended(groups.membership_ended_on_commit)
# A STOP and the queues it holds or releases show on the tablets.
cobot_hooks.register_tablets(
    queue_changed=groups.cobot_queue_on_commit, stop_changed=groups.cell_stop_on_commit
)
# What cases record reaches the tablets after commit.
case_events.register_publisher(
    case_event=groups.case_event_on_commit,
    cobot_queue=groups.cobot_queue_on_commit,
    hold=groups.hold,
)
