"""/api/analytics/…: a version's figures, a case's Gantt chart, the XES export."""

from django.urls import path

from hrc.analytics.api.views import CaseGanttView, VersionAnalyticsView, XesExportView

urlpatterns = [
    path("analytics/versions/<int:pk>/", VersionAnalyticsView.as_view(), name="analytics-version"),
    path("analytics/cases/<int:pk>/gantt/", CaseGanttView.as_view(), name="analytics-case-gantt"),
    path("analytics/xes/", XesExportView.as_view(), name="analytics-xes"),
]
