"""The record of the tablets' STOPs, read-only: they are made and ended on the tablets only.

Registered here, not in the cobots app that keeps them, for the read-only
admin of the runtime's rows (hrc.cases.admin), which cobots cannot import.
"""

from django.contrib import admin

from hrc.cases.admin import ReadOnlyAdmin
from hrc.cobots.models import CellStop


@admin.register(CellStop)
class CellStopAdmin(ReadOnlyAdmin):
    list_display = ["stopped_at", "organisation", "cell", "stopped_by", "resumed_at", "resumed_by"]
    list_filter = ["organisation"]
