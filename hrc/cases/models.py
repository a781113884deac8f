"""Running cases: a published pattern version at work, its work items, jobs, events and incidents.

The rows are the truth. A case's marking and data live on its row, which is
the lock every change to the case takes (select_for_update); work items are
the tasks the marking offers; a job is one command to a cobot (a step or a
device call) and holds its own lease, so a Celery message carries nothing
but the job's id. Events are appended, never changed: the audit trail and
the timeline. Writes go through hrc.cases.services only.
"""

from typing import Any

from django.conf import settings
from django.db import models
from django.db.models import Q

from hrc.cases import rows
from hrc.cases.choices import (
    OPEN_WORK_ITEM_STATES,
    CaseStatus,
    EventType,
    IncidentKind,
    InterruptionMode,
    JobState,
    Resolution,
    TimerState,
    WorkItemKind,
    WorkItemState,
)
from hrc.cobots.models import Cobot, Device
from hrc.organisations.models import Organisation, Team
from hrc.patterns.models import PatternVersion

_USER = settings.AUTH_USER_MODEL


class Case(models.Model):
    organisation = models.ForeignKey(
        Organisation, on_delete=models.CASCADE, related_name="cases",
        help_text="The organisation the case runs in; only its members see it.",
    )  # fmt: skip
    version = models.ForeignKey(
        PatternVersion, on_delete=models.PROTECT, related_name="cases",
        help_text="The published pattern version the case runs.",
    )  # fmt: skip
    status = models.CharField(max_length=20, choices=CaseStatus.choices, default=CaseStatus.RUNNING)
    marking = models.JSONField(default=dict, help_text="Tokens per place of the execution net.")
    data = models.JSONField(
        default=dict, blank=True, help_text="The case data tasks read and write."
    )
    actor_mapping = models.JSONField(
        help_text="Who performs each pattern actor: {actor: {users: [ids]} | {team: id} | {cobot: id}}."
    )
    started_by = models.ForeignKey(
        _USER, on_delete=models.SET_NULL, null=True, blank=True, related_name="+"
    )
    reference = models.CharField(
        max_length=100,
        blank=True,
        help_text="What the case works on, as the plant names it: an order or workpiece number.",
    )
    started_at = models.DateTimeField(auto_now_add=True)
    ended_at = models.DateTimeField(null=True, blank=True)
    last_seq = models.PositiveIntegerField(
        default=0, help_text="The sequence number of the case's latest event."
    )
    timer_scale = models.FloatField(
        default=1.0,
        help_text="Its timers wait their duration times this: 1 on a plant, less in a "
        "simulation that runs faster than real time (run_pattern --time-scale, --timer-scale).",
    )

    class Meta:
        ordering = ["-started_at", "-id"]
        indexes = [models.Index(fields=["organisation", "status"])]

    def __str__(self) -> str:
        return f"case {self.pk} of {self.version}"

    def save(self, *args: Any, **kwargs: Any) -> None:
        """Saves the case with the events logged and the rows kept for it since it was read, in
        one statement (the case's CHANGING_FIELDS unless update_fields says)."""
        events: list[CaseEvent] = self.__dict__.pop("_unwritten_events", [])
        rows_kept: list[tuple[models.Model, list[str]]] = self.__dict__.pop("_unwritten_rows", [])
        if self._state.adding or args or not set(kwargs) <= {"update_fields"}:
            for row, changed in rows_kept:
                rows.update(row, changed)
            super().save(*args, **kwargs)
            CaseEvent.objects.bulk_create(events)
            return
        fields = kwargs.get("update_fields") or CHANGING_FIELDS
        rows.save_with(self, fields, inserts=events, updates=rows_kept)

    def log(self, event: "CaseEvent") -> None:
        """Keeps an event of this case for the next save(), which writes it (events.record_event):
        a transaction writes its case's events and the case in one statement, not one each."""
        self.__dict__.setdefault("_unwritten_events", []).append(event)

    def keep(self, row: models.Model, fields: list[str]) -> None:
        """Keeps these fields of a row of this case (its job, say) for the next save(), which
        writes them with the case. Only for a row nothing reads before the case is saved."""
        self.__dict__.setdefault("_unwritten_rows", []).append((row, fields))


# The columns of a case that change after its start: what save() writes with its events.
CHANGING_FIELDS = ("status", "marking", "data", "ended_at", "last_seq")


class WorkItem(models.Model):
    """One offer of a task in a case: to operators' task lists, or to a cobot's queue."""

    case = models.ForeignKey(Case, on_delete=models.CASCADE, related_name="work_items")
    task = models.CharField(max_length=200, help_text="The pattern transition's id.")
    label = models.CharField(max_length=300, blank=True)
    actor = models.CharField(max_length=200, help_text="The pattern actor who performs it.")
    kind = models.CharField(max_length=20, choices=WorkItemKind.choices)
    state = models.CharField(
        max_length=20, choices=WorkItemState.choices, default=WorkItemState.OFFERED
    )
    instructions = models.TextField(blank=True)
    candidates: "models.ManyToManyField[Any, Any]" = models.ManyToManyField(
        _USER, blank=True, related_name="candidate_work_items",
        help_text="Operators who may take it (with the team's members, when a team is mapped).",
    )  # fmt: skip
    team = models.ForeignKey(Team, on_delete=models.SET_NULL, null=True, blank=True)
    cobot = models.ForeignKey(Cobot, on_delete=models.PROTECT, null=True, blank=True)
    device = models.ForeignKey(
        Device, on_delete=models.PROTECT, null=True, blank=True, related_name="work_items",
        help_text="The device a device call runs on (its own queue, not its cobot's).",
    )  # fmt: skip
    claimed_by = models.ForeignKey(
        _USER, on_delete=models.SET_NULL, null=True, blank=True, related_name="+"
    )
    completed_by = models.ForeignKey(
        _USER, on_delete=models.SET_NULL, null=True, blank=True, related_name="+"
    )
    result = models.JSONField(null=True, blank=True, help_text="Form data or the cobot's answer.")
    offered_at = models.DateTimeField(auto_now_add=True)
    started_at = models.DateTimeField(null=True, blank=True)
    ended_at = models.DateTimeField(null=True, blank=True)

    class Meta:
        ordering = ["offered_at", "id"]
        constraints = [
            # One open offer per task and case: a second offer would let it run twice.
            models.UniqueConstraint(
                fields=["case", "task"],
                condition=Q(state__in=sorted(OPEN_WORK_ITEM_STATES)),
                name="work_item_one_open_per_task",
            )
        ]
        indexes = [
            models.Index(fields=["state", "kind"]),
            # Whether another case's func hold reserves a job's cobot is asked per queued job
            # (the sweeper's read, a lease's queue): through this, a few running items, not
            # every item the cobot ever had (bench/README.md, "A cobot's running items").
            models.Index(fields=["cobot", "state"]),
        ]

    def __str__(self) -> str:
        return f"{self.label or self.task} ({self.state})"


class CaseTimer(models.Model):
    """A timer transition of a case, armed while it is enabled: it fires once it has been
    enabled for its duration without interruption (progress.arm_timers, timers.ring_timer)."""

    case = models.ForeignKey(Case, on_delete=models.CASCADE, related_name="timers")
    transition = models.CharField(max_length=200, help_text="The timer transition's id.")
    label = models.CharField(
        max_length=200, blank=True, help_text="The timer transition's label, as tablets show it."
    )
    state = models.CharField(max_length=10, choices=TimerState.choices, default=TimerState.ARMED)
    armed_at = models.DateTimeField(auto_now_add=True)
    due_at = models.DateTimeField(
        help_text="When it rings: armed_at + duration × the case's timer scale."
    )
    ended_at = models.DateTimeField(null=True, blank=True, help_text="Fired or disarmed.")

    class Meta:
        ordering = ["due_at", "id"]
        constraints = [
            # One armed timer per transition and case: two would fire it twice.
            models.UniqueConstraint(
                fields=["case", "transition"],
                condition=Q(state="armed"),
                name="case_timer_one_armed_per_transition",
            )
        ]
        indexes = [models.Index(fields=["state", "due_at"])]

    def __str__(self) -> str:
        return f"timer {self.transition} of case {self.case_id} ({self.state})"


class Job(models.Model):
    """A command to a cobot or a device for a work item: the row is the lock, the Celery message
    only its id. A device call is the device's job, in the device's queue (cases.device_jobs).

    The fencing token sent with a step is (id, attempt). `attempt` changes
    only when a person asks for the step to run again; automatic retries and
    re-acquired leases keep it, so the cobot recognises a step it has run.
    `lease` counts acquisitions: a worker whose lease is not the row's any
    more has lost the job and may change nothing.
    """

    work_item = models.OneToOneField(WorkItem, on_delete=models.CASCADE, related_name="job")
    case = models.ForeignKey(Case, on_delete=models.CASCADE, related_name="jobs")
    cobot = models.ForeignKey(
        Cobot, on_delete=models.PROTECT, null=True, blank=True, related_name="jobs"
    )
    device = models.ForeignKey(
        Device, on_delete=models.PROTECT, null=True, blank=True, related_name="jobs"
    )
    kind = models.CharField(max_length=20, choices=WorkItemKind.choices)
    command = models.JSONField(
        help_text="Step: program, number, workspace, poses. Device: method, args."
    )
    state = models.CharField(max_length=20, choices=JobState.choices, default=JobState.QUEUED)
    attempt = models.PositiveIntegerField(default=1)
    lease = models.PositiveIntegerField(default=0)
    lease_expires_at = models.DateTimeField(null=True, blank=True)
    lease_expiries = models.PositiveIntegerField(default=0)
    held_by = models.CharField(
        max_length=100, blank=True, help_text="host:pid of the worker that holds the lease."
    )
    retries_left = models.PositiveIntegerField(default=3)
    timeout = models.FloatField(help_text="Seconds the step or call may take.")
    queued_at = models.DateTimeField(auto_now_add=True, help_text="Its place in the cobot's queue.")
    next_try_at = models.DateTimeField(help_text="Not before: the back-off after a failure.")
    sent_at = models.DateTimeField(null=True, blank=True, help_text="When a device call went out.")
    started_at = models.DateTimeField(null=True, blank=True)
    accepted_at = models.DateTimeField(
        null=True,
        blank=True,
        help_text="When the cobot accepted the step of the attempt that ended the job (a device "
        "call: when it went out); the cobot worked from here to ended_at.",
    )
    ended_at = models.DateTimeField(null=True, blank=True)
    waiting_for = models.CharField(max_length=300, blank=True, help_text="Why it has not started.")
    last_error = models.TextField(blank=True)
    result = models.JSONField(null=True, blank=True)

    class Meta:
        ordering = ["queued_at", "id"]
        indexes = [
            models.Index(fields=["cobot", "state", "queued_at"]),
            models.Index(fields=["device", "state", "queued_at"]),
            # The sweeper's reads, every few seconds: the jobs waiting or running, a handful
            # however many the plant has run.
            models.Index(
                fields=["queued_at", "id"],
                condition=Q(state=JobState.QUEUED),
                name="job_queued",
            ),
            models.Index(
                fields=["started_at", "id"],
                condition=Q(state=JobState.RUNNING),
                name="job_running",
            ),
        ]
        constraints = [
            # In one queue exactly: a cobot's or a device's.
            models.CheckConstraint(
                condition=Q(cobot__isnull=True) ^ Q(device__isnull=True),
                name="job_on_a_cobot_or_a_device",
            )
        ]

    def __str__(self) -> str:
        on = f"cobot {self.cobot_id}" if self.cobot_id else f"device {self.device_id}"
        return f"job {self.pk} ({self.kind} on {on}, {self.state})"

    @property
    def fence(self) -> tuple[int, int]:
        return (self.pk, self.attempt)


class Interruption(models.Model):
    """A task held while another works in a shared area (space constraint): a cobot's step
    paused or slowed while it runs, or a task kept out until the other completes (an
    operator refused, a cobot's step waiting). `work_item` is the task held, `by_work_item`
    the one in the area; both actors are theirs (WorkItem.actor).

    For a pause or a slowdown the command and its undoing are each sent at most once, by
    the task that claimed the row (claimed_at) and sends outside any transaction
    (hrc.cases.interruptions); a resume that finds no pause sent marks it never needed.
    A wait or a refusal sends nothing: it only ends.
    """

    case = models.ForeignKey(Case, on_delete=models.CASCADE, related_name="interruptions")
    work_item = models.ForeignKey(WorkItem, on_delete=models.CASCADE, related_name="interruptions")
    by_work_item = models.ForeignKey(WorkItem, on_delete=models.CASCADE, related_name="+")
    cobot = models.ForeignKey(
        Cobot, on_delete=models.PROTECT, related_name="interruptions", null=True, blank=True,
        help_text="The held task's cobot; none when an operator is refused.",
    )  # fmt: skip
    mode = models.CharField(max_length=10, choices=InterruptionMode.choices)
    started_at = models.DateTimeField(auto_now_add=True)
    ended_at = models.DateTimeField(null=True, blank=True)
    paused_at = models.DateTimeField(null=True, blank=True)
    resumed_at = models.DateTimeField(null=True, blank=True)
    error = models.TextField(blank=True)
    claimed_at = models.DateTimeField(
        null=True, blank=True, help_text="Set while one sender sends its pause or resume."
    )

    class Meta:
        ordering = ["started_at", "id"]

    def __str__(self) -> str:
        return f"{self.mode} of work item {self.work_item_id} by {self.by_work_item_id}"

    @property
    def settled(self) -> bool:
        """Over, and the cobot no longer paused (or slowed) by it."""
        return self.ended_at is not None and (self.paused_at is None or self.resumed_at is not None)

    @property
    def seconds(self) -> float | None:
        """How long it lasted; None while it goes on."""
        if self.ended_at is None:
            return None
        return round((self.ended_at - self.started_at).total_seconds(), 3)


class Incident(models.Model):
    """Something a person must decide: retry, skip with given outputs, or cancel the case."""

    case = models.ForeignKey(Case, on_delete=models.CASCADE, related_name="incidents")
    work_item = models.ForeignKey(WorkItem, on_delete=models.CASCADE, null=True, blank=True)
    kind = models.CharField(max_length=20, choices=IncidentKind.choices)
    message = models.TextField()
    cobot_state = models.JSONField(
        null=True, blank=True, help_text="The cobot's state when it failed."
    )
    opened_at = models.DateTimeField(auto_now_add=True)
    resolved_at = models.DateTimeField(null=True, blank=True)
    resolution = models.CharField(max_length=10, choices=Resolution.choices, blank=True)
    resolved_by = models.ForeignKey(
        _USER, on_delete=models.SET_NULL, null=True, blank=True, related_name="+"
    )

    class Meta:
        ordering = ["-opened_at", "-id"]

    def __str__(self) -> str:
        return f"{self.get_kind_display()} in case {self.case_id}"


class ImmutableEventError(Exception):
    """An event was about to be changed; the log is append-only."""


class CaseEvent(models.Model):
    """One entry of a case's append-only log: who did what, when, and the marking around it."""

    case = models.ForeignKey(Case, on_delete=models.CASCADE, related_name="events")
    seq = models.PositiveIntegerField(help_text="1, 2, 3… within the case.")
    at = models.DateTimeField()
    type = models.CharField(max_length=30, choices=EventType.choices)
    task = models.CharField(max_length=200, blank=True)
    actor = models.CharField(max_length=200, blank=True, help_text="The pattern actor.")
    work_item = models.ForeignKey(
        WorkItem, on_delete=models.SET_NULL, null=True, blank=True, related_name="+"
    )
    user = models.ForeignKey(
        _USER, on_delete=models.SET_NULL, null=True, blank=True, related_name="+"
    )
    marking_before = models.JSONField(default=dict)
    marking_after = models.JSONField(default=dict)
    detail = models.JSONField(default=dict, blank=True)

    class Meta:
        ordering = ["case", "seq"]
        constraints = [
            models.UniqueConstraint(fields=["case", "seq"], name="case_event_seq_unique")
        ]

    def __str__(self) -> str:
        return f"{self.seq}. {self.type} {self.task}".strip()

    def save(self, *args: Any, **kwargs: Any) -> None:
        if not self._state.adding:
            raise ImmutableEventError(f"Event {self.seq} of case {self.case_id} cannot be changed.")
        super().save(*args, **kwargs)


class Message(models.Model):
    """A message sent to cases (POST /api/messages/, or by a case's `send`); kept until
    consumed or expired."""

    organisation = models.ForeignKey(
        Organisation, on_delete=models.CASCADE, related_name="messages"
    )
    message_id = models.CharField(
        max_length=200, help_text="The sender's id: a repeated send with it changes nothing."
    )
    name = models.CharField(max_length=200)
    correlation = models.JSONField(default=dict, blank=True)
    payload = models.JSONField(default=dict, blank=True)
    received_at = models.DateTimeField(auto_now_add=True)
    expires_at = models.DateTimeField()
    case = models.ForeignKey(
        Case, on_delete=models.SET_NULL, null=True, blank=True, related_name="messages"
    )
    transition = models.CharField(max_length=200, blank=True)
    consumed_at = models.DateTimeField(null=True, blank=True)
    sent_by = models.ForeignKey(_USER, on_delete=models.SET_NULL, null=True, related_name="+")
    # A message a case sent (sent_by is then null), and the transition that sent it.
    sent_from_case = models.ForeignKey(
        Case, on_delete=models.SET_NULL, null=True, blank=True, related_name="sent_messages"
    )
    sent_from_transition = models.CharField(max_length=200, blank=True)
    # When a case's message was offered to the other cases after its sender committed; until
    # then the sweeper rings for it again (its doorbell may have been lost).
    offered_at = models.DateTimeField(null=True, blank=True)

    class Meta:
        ordering = ["received_at", "id"]
        constraints = [
            models.UniqueConstraint(
                fields=["organisation", "message_id"], name="message_id_unique_in_organisation"
            )
        ]
        indexes = [models.Index(fields=["organisation", "name", "consumed_at"])]

    def __str__(self) -> str:
        return f"{self.name} ({self.message_id})"
