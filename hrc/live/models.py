"""What the live layer keeps: the record of every STOP a tablet gave and its resume."""

from django.conf import settings
from django.db import models

from hrc.organisations.models import Organisation

_USER = settings.AUTH_USER_MODEL


class CellStop(models.Model):
    """A tablet's STOP: every cobot of the cell paused until someone confirms resuming.

    A convenience, not a safety function: the robots' own safety systems stay in
    charge, and nothing here clears a protective or emergency stop.
    """

    organisation = models.ForeignKey(
        Organisation, on_delete=models.CASCADE, related_name="cell_stops"
    )
    cell = models.CharField(max_length=50, blank=True, help_text="Empty: the whole floor.")
    stopped_by = models.ForeignKey(_USER, on_delete=models.SET_NULL, null=True, related_name="+")
    stopped_at = models.DateTimeField(auto_now_add=True)
    resumed_by = models.ForeignKey(
        _USER, on_delete=models.SET_NULL, null=True, blank=True, related_name="+"
    )
    resumed_at = models.DateTimeField(null=True, blank=True)
    cobots = models.JSONField(default=list, help_text="The ids of the cobots it paused.")
    problems = models.JSONField(
        default=dict, blank=True, help_text="Cobot id → why it could not be paused or resumed."
    )

    class Meta:
        ordering = ["-stopped_at", "-id"]
        constraints = [
            # One STOP holds a cell at a time: a second press finds the first.
            models.UniqueConstraint(
                fields=["organisation", "cell"],
                condition=models.Q(resumed_at__isnull=True),
                name="cell_stop_one_active_per_cell",
            )
        ]

    def __str__(self) -> str:
        return f"STOP of {self.cell or 'the floor'} at {self.stopped_at:%H:%M:%S}"
