"""The cases app's answers to the inner apps' hooks, registered when Django is ready (apps.py)."""

from hrc.cases import (
    device_jobs,
    interruptions,
    selectors,
    services,
    tasks,  # noqa: F401  (registers them, so dispatch finds them by name inline)
)
from hrc.cobots import hooks as cobot_hooks
from hrc.organisations import hooks as organisation_hooks

# The cobots app asks whether a case is using a cobot before a person's command.
cobot_hooks.register_cobot_use(
    in_use=selectors.cobot_in_use, queue_lengths=selectors.cobot_queue_lengths
)
# A STOP's resume restarts no cobot an operator's interruption holds, and starts the queues.
cobot_hooks.register_cobot_queues(
    held_by_interruption=interruptions.holds_cobot,
    queue_released=interruptions.ring_next_job_on_commit,
)
# A device's queue: rung when its cell's STOP ends, shown on the cobot and device pages.
cobot_hooks.register_device_queues(
    devices_released=device_jobs.ring_devices_on_commit, device_queues=selectors.device_queues
)
# A deactivated person's tasks go back to their candidates.
organisation_hooks.register_member_leaving(services.hand_back_work_items)
