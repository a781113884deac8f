"""Request bodies of the live layer's API."""

from typing import Any

from rest_framework import serializers

from hrc.organisations.validators import validate_cell


class CellRequestSerializer(serializers.Serializer[dict[str, Any]]):
    organisation = serializers.IntegerField(
        required=False, help_text="Needed only when you belong to several organisations."
    )
    cell = serializers.CharField(
        required=False, allow_blank=True, default="", max_length=50,
        validators=[validate_cell], help_text="The cell, one of the organisation's (required).",
    )  # fmt: skip


class ResumeRequestSerializer(CellRequestSerializer):
    confirm = serializers.BooleanField(
        default=False, help_text="Must be true: resuming a stopped cell is confirmed on the tablet."
    )


class CellStopSerializer(serializers.Serializer[dict[str, Any]]):
    """A STOP as the tablets show it (hrc.live.events.CellStopData)."""

    id = serializers.IntegerField()
    cell = serializers.CharField()
    stopped_by = serializers.CharField()
    stopped_at = serializers.CharField()
    resumed_by = serializers.CharField()
    resumed_at = serializers.CharField(allow_null=True)
    cobots = serializers.ListField(child=serializers.IntegerField())
    problems = serializers.DictField(child=serializers.CharField())
