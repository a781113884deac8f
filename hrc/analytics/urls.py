"""The analytics pages: /analytics/, /analytics/versions/<id>/, /analytics/cases/<id>/gantt/
(the API's routes are api/urls.py)."""

from django.urls import path

from hrc.analytics import views

app_name = "analytics"

urlpatterns = [
    path("analytics/", views.version_list, name="version-list"),
    path("analytics/versions/<int:pk>/", views.version_detail, name="version-detail"),
    path("analytics/cases/<int:pk>/gantt/", views.case_gantt, name="case-gantt"),
]
