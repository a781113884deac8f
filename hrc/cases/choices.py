"""Fixed vocabularies of the cases app."""

from django.db import models


class CaseStatus(models.TextChoices):
    RUNNING = "running", "Running"
    # Nothing new is offered or dispatched; work already under way finishes.
    SUSPENDED = "suspended", "Suspended"
    COMPLETED = "completed", "Completed"
    CANCELLED = "cancelled", "Cancelled"
    # The model cannot go on (a guard failed, a silent loop); an incident says why.
    FAILED = "failed", "Failed"


OPEN_CASE_STATUSES = frozenset({CaseStatus.RUNNING, CaseStatus.SUSPENDED})


class WorkItemKind(models.TextChoices):
    OPERATOR = "operator", "Operator task"
    # A program step on a cobot, through the step handshake.
    STEP = "step", "Cobot step"
    # A device call (linear axis, part detection, inspection, display) on a cobot's gateway.
    DEVICE = "device", "Device call"


class WorkItemState(models.TextChoices):
    # Offered to its candidates (operator) or queued for its cobot (step, device).
    OFFERED = "offered", "Offered"
    # An operator took it; nobody else sees it as open.
    CLAIMED = "claimed", "Claimed"
    RUNNING = "running", "Running"
    COMPLETED = "completed", "Completed"
    # Another task of a deferred choice started first, or the case ended.
    WITHDRAWN = "withdrawn", "Withdrawn"
    # Stopped counting while it ran: a transition's `cancels` emptied its task. A cobot's step
    # already on the cobot runs to its end (only a person stops a cobot); nothing follows from it.
    CANCELLED = "cancelled", "Cancelled"


OPEN_WORK_ITEM_STATES = frozenset(
    {WorkItemState.OFFERED, WorkItemState.CLAIMED, WorkItemState.RUNNING}
)


class JobState(models.TextChoices):
    # Waiting in its cobot's queue (first come, first served), perhaps until next_try_at.
    QUEUED = "queued", "Queued"
    # A worker holds the lease and is driving the cobot.
    RUNNING = "running", "Running"
    SUCCEEDED = "succeeded", "Succeeded"
    # Out of retries or refused: an incident waits for a person.
    FAILED = "failed", "Failed"
    CANCELLED = "cancelled", "Cancelled"


class IncidentKind(models.TextChoices):
    STEP_FAILED = "step-failed", "Cobot step failed"
    DEVICE_FAILED = "device-failed", "Device call failed"
    # Workers kept losing the job (killed, stuck): the lease expired too often.
    LEASE_EXPIRED = "lease-expired", "Worker lost the job repeatedly"
    # The model cannot go on: a guard or an output expression failed on the case data.
    CASE_FAULT = "case-fault", "Case fault"


class Resolution(models.TextChoices):
    RETRY = "retry", "Retry"
    # The task counts as completed with the outputs the person gives.
    SKIP = "skip", "Skip with given outputs"
    CANCEL = "cancel", "Cancel the case"


class InterruptionMode(models.TextChoices):
    PAUSE = "pause", "Pause"
    # The speed override is lowered instead of pausing (where the cobot supports it).
    SLOW = "slow", "Slow down"
    # Kept out until the task in the area completes: a cobot's step waits, an operator is refused.
    WAIT = "wait", "Wait for the area"
    REFUSED = "refused", "Refused"


# The modes that command the cobot (and undo it after); a wait or a refusal only ends.
COMMANDED_MODES = (InterruptionMode.PAUSE, InterruptionMode.SLOW)


class TimerState(models.TextChoices):
    # Its transition is enabled; it rings at due_at unless the transition stops being enabled.
    ARMED = "armed", "Armed"
    FIRED = "fired", "Fired"
    # Its transition stopped being enabled before it was due (another branch went first).
    DISARMED = "disarmed", "Disarmed"


class EventType(models.TextChoices):
    CASE_STARTED = "case-started", "Case started"
    CASE_SUSPENDED = "case-suspended", "Case suspended"
    CASE_RESUMED = "case-resumed", "Case resumed"
    CASE_CANCELLED = "case-cancelled", "Case cancelled"
    CASE_COMPLETED = "case-completed", "Case completed"
    CASE_FAILED = "case-failed", "Case failed"
    TASK_OFFERED = "task-offered", "Task offered"
    TASK_CLAIMED = "task-claimed", "Task claimed"
    TASK_UNCLAIMED = "task-unclaimed", "Task unclaimed"
    # A supervisor gave a task to another operator, or back to its candidates.
    TASK_REASSIGNED = "task-reassigned", "Task reassigned"
    TASK_STARTED = "task-started", "Task started"
    TASK_COMPLETED = "task-completed", "Task completed"
    TASK_WITHDRAWN = "task-withdrawn", "Task withdrawn"
    # A running task stopped counting: the transition in its detail (`by`) cancelled it.
    TASK_CANCELLED = "task-cancelled", "Task cancelled"
    # The step of a cancelled task ended on its cobot; its outcome is kept, nothing fires.
    CANCELLED_STEP_ENDED = "cancelled-step-ended", "Cancelled task's step ended"
    TASK_INTERRUPTED = "task-interrupted", "Task interrupted"
    TASK_RESUMED = "task-resumed", "Task resumed"
    # A person said the operator of a cancelled task has left its shared area: what the
    # operator's presence paused or slowed resumes (the cancellation alone does not).
    AREA_LEFT = "area-left", "Operator left the area"
    # Refused (an operator) or held back (a cobot's step) while another task is in its shared area.
    TASK_KEPT_OUT = "task-kept-out", "Task kept out of a shared area"
    # A silent (routing) transition fired.
    TRANSITION_FIRED = "transition-fired", "Transition fired"
    # The case sent a message as a task completed or a transition fired (a "send" key).
    MESSAGE_SENT = "message-sent", "Message sent"
    MESSAGE_RECEIVED = "message-received", "Message received"
    # A timer transition became enabled: it fires at due_at unless disabled before (disarmed).
    TIMER_ARMED = "timer-armed", "Timer armed"
    # A timer transition fired: it had been enabled for its duration without interruption.
    TIMER_FIRED = "timer-fired", "Timer fired"
    # An armed timer's transition was disabled before it was due: it will not fire.
    TIMER_DISARMED = "timer-disarmed", "Timer disarmed"
    STEP_RETRY = "step-retry", "Step will be retried"
    # A cobot step or device call failed for good: its error; an incident follows.
    STEP_FAILED = "step-failed", "Step failed"
    INCIDENT_OPENED = "incident-opened", "Incident opened"
    INCIDENT_RESOLVED = "incident-resolved", "Incident resolved"
