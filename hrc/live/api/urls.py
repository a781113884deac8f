"""/api/cells/stop/ and /api/cells/resume/."""

from django.urls import path

from hrc.live.api.views import ResumeCellView, StopCellView

urlpatterns = [
    path("cells/stop/", StopCellView.as_view(), name="cell-stop"),
    path("cells/resume/", ResumeCellView.as_view(), name="cell-resume"),
]
