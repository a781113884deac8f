"""The analytics answers as JSON: read-only serializers over hrc.analytics' dataclasses.

Durations are seconds (floats); a summary's figures are null when it counts
nothing. Times are ISO 8601.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from drf_spectacular.utils import extend_schema_field
from rest_framework import serializers

from hrc.analytics.gantt import Gantt
from hrc.analytics.metrics import VersionFigures
from hrc.patterns.models import PatternVersion


class SummarySerializer(serializers.Serializer[Any]):
    """Durations in seconds: how many, their sum, mean, extremes and percentiles
    (linear interpolation between closest ranks)."""

    count = serializers.IntegerField()
    total = serializers.FloatField()
    mean = serializers.FloatField(allow_null=True)
    min = serializers.FloatField(allow_null=True)
    p50 = serializers.FloatField(allow_null=True)
    p90 = serializers.FloatField(allow_null=True)
    p99 = serializers.FloatField(allow_null=True)
    max = serializers.FloatField(allow_null=True)


class WindowSerializer(serializers.Serializer[Any]):
    """From the first analysed case's start to the last one's end (now while one runs)."""

    start = serializers.DateTimeField()
    end = serializers.DateTimeField()


class CaseFiguresSerializer(serializers.Serializer[Any]):
    id = serializers.IntegerField()
    status = serializers.CharField()
    started_at = serializers.DateTimeField()
    ended_at = serializers.DateTimeField(allow_null=True)
    cycle_seconds = serializers.FloatField(
        allow_null=True, help_text="Start to end; null unless the case completed."
    )
    interruptions = serializers.IntegerField()


class TaskFiguresSerializer(serializers.Serializer[Any]):
    task = serializers.CharField(help_text="The pattern transition's id.")
    label = serializers.CharField()  # type: ignore[assignment]  # DRF takes declared fields off the class
    actor = serializers.CharField()
    kind = serializers.CharField(help_text="operator, step or device.")
    offered = serializers.IntegerField(help_text="Work items of this task.")
    completed = serializers.IntegerField()
    withdrawn = serializers.IntegerField()
    work = SummarySerializer(help_text="Started to completed (the task's cycle time).")
    wait = SummarySerializer(help_text="Offered to started.")


class CobotFiguresSerializer(serializers.Serializer[Any]):
    cobot = serializers.IntegerField(source="cobot_id")
    name = serializers.CharField(source="cobot")
    jobs = serializers.IntegerField(help_text="Jobs of these cases that ran on it.")
    busy_seconds = serializers.FloatField(
        help_text="Time within the window at least one of those jobs ran (overlaps once)."
    )
    window_seconds = serializers.FloatField()
    utilisation = serializers.FloatField(
        allow_null=True, help_text="busy_seconds / window_seconds, 0 to 1."
    )
    queue_wait = SummarySerializer(help_text="Queued to started.")


class InterruptionFiguresSerializer(serializers.Serializer[Any]):
    count = serializers.IntegerField()
    ongoing = serializers.IntegerField()
    by_mode = serializers.DictField(child=serializers.IntegerField())
    by_cobot = serializers.DictField(child=serializers.IntegerField())
    duration = SummarySerializer(help_text="Start to end, of those that ended.")
    paused = SummarySerializer(help_text="Pause sent to resume sent.")


@dataclass(frozen=True)
class VersionReport:
    version: PatternVersion
    since: Any
    until: Any
    figures: VersionFigures


class VersionAnalyticsSerializer(serializers.Serializer[VersionReport]):
    version = serializers.IntegerField(source="version.pk")
    pattern = serializers.CharField(source="version.pattern.name")
    number = serializers.IntegerField(source="version.number")
    since = serializers.DateTimeField(allow_null=True)
    until = serializers.DateTimeField(allow_null=True)
    now = serializers.DateTimeField(source="figures.now", help_text="When this was measured.")
    cases = serializers.IntegerField(source="figures.cases", help_text="Cases analysed.")
    by_status = serializers.DictField(child=serializers.IntegerField(), source="figures.by_status")
    window = serializers.SerializerMethodField()
    cycle = SummarySerializer(
        source="figures.cycle", help_text="Cycle time of the completed cases: start to end."
    )
    recent_cases = CaseFiguresSerializer(
        many=True, source="figures.recent_cases", help_text="The newest 100 cases."
    )
    tasks = TaskFiguresSerializer(many=True, source="figures.tasks")
    operator_waiting = SummarySerializer(
        source="figures.operator_waiting",
        help_text="Offered to started, over the operator tasks that started.",
    )
    cobots = CobotFiguresSerializer(many=True, source="figures.cobots")
    interruptions = InterruptionFiguresSerializer(source="figures.interruptions")

    @extend_schema_field(WindowSerializer(allow_null=True))
    def get_window(self, report: VersionReport) -> dict[str, Any] | None:
        window = report.figures.window
        if window is None:
            return None
        return dict(WindowSerializer({"start": window[0], "end": window[1]}).data)


# The Gantt chart ---------------------------------------------------------------------------


class BarSerializer(serializers.Serializer[Any]):
    work_item = serializers.IntegerField()
    task = serializers.CharField()
    label = serializers.CharField()  # type: ignore[assignment]  # DRF takes declared fields off the class
    kind = serializers.CharField()
    state = serializers.CharField()
    resource = serializers.CharField(help_text="The operator's user name or the cobot's name.")
    offered_at = serializers.DateTimeField()
    started_at = serializers.DateTimeField(allow_null=True)
    ended_at = serializers.DateTimeField(allow_null=True, help_text="null while it is open.")
    lane = serializers.IntegerField(help_text="0, 1…: bars of one actor that overlap in time.")


class GanttRowSerializer(serializers.Serializer[Any]):
    actor = serializers.CharField()
    type = serializers.CharField(help_text="cobot or operator.")
    who = serializers.CharField(help_text="Who performs the actor in this case.")
    lanes = serializers.IntegerField()
    bars = BarSerializer(many=True)


class GanttConstraintSerializer(serializers.Serializer[Any]):
    index = serializers.IntegerField(help_text="Its position in the document's constraints.")
    source = serializers.CharField()  # type: ignore[assignment]  # DRF takes declared fields off the class
    target = serializers.CharField()
    type = serializers.CharField()


class ArrowSerializer(serializers.Serializer[Any]):
    constraint = serializers.IntegerField(help_text="The constraint's index.")
    type = serializers.CharField()
    source = serializers.CharField()  # type: ignore[assignment]  # DRF takes declared fields off the class
    target = serializers.CharField()
    from_work_item = serializers.IntegerField()
    to_work_item = serializers.IntegerField()
    from_at = serializers.DateTimeField()
    to_at = serializers.DateTimeField()
    overlapping = serializers.BooleanField(help_text="Both bars ran at from_at.")


class MarkSerializer(serializers.Serializer[Any]):
    interruption = serializers.IntegerField()
    work_item = serializers.IntegerField(help_text="The task held: paused, slowed or kept out.")
    actor = serializers.CharField(help_text="The held task's pattern actor.")
    by_work_item = serializers.IntegerField(help_text="The task in the shared area.")
    by_task = serializers.CharField()
    by_label = serializers.CharField()
    by_actor = serializers.CharField(help_text="The pattern actor in the shared area.")
    cobot = serializers.CharField(
        allow_null=True, help_text="The held cobot; null for an operator."
    )
    mode = serializers.CharField()
    started_at = serializers.DateTimeField()
    ended_at = serializers.DateTimeField(allow_null=True)
    paused_at = serializers.DateTimeField(allow_null=True)
    resumed_at = serializers.DateTimeField(allow_null=True)


class GanttSerializer(serializers.Serializer[Gantt]):
    case = serializers.IntegerField()
    start = serializers.DateTimeField()
    end = serializers.DateTimeField(help_text="The case's end, or now while it runs.")
    now = serializers.DateTimeField()
    open = serializers.BooleanField()
    rows = GanttRowSerializer(many=True)
    constraints = GanttConstraintSerializer(many=True)
    arrows = ArrowSerializer(many=True)
    marks = MarkSerializer(many=True, help_text="Interruptions.")
