"""The record of the tablets' STOPs, read-only: they are made and ended on the tablets only."""

from django.contrib import admin

from hrc.cases.admin import ReadOnlyAdmin
from hrc.live.models import CellStop


@admin.register(CellStop)
class CellStopAdmin(ReadOnlyAdmin):
    list_display = ["stopped_at", "organisation", "cell", "stopped_by", "resumed_at", "resumed_by"]
    list_filter = ["organisation"]
