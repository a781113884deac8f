"""The supervisor pages: /cases/ (and starting them), /cases/<id>/, /incidents/, and a published
version's page /patterns/versions/<id>/, where it is run from (the API's routes are api/urls.py)."""

from django.urls import path

from hrc.cases import views

app_name = "cases"

urlpatterns = [
    path("cases/", views.case_list, name="case-list"),
    path("cases/new/", views.case_start, name="case-start"),
    path("cases/<int:pk>/", views.case_detail, name="case-detail"),
    path("cases/<int:pk>/control/", views.case_control, name="case-control"),
    path("patterns/versions/<int:pk>/", views.version_detail, name="version"),
    path("incidents/", views.incident_list, name="incident-list"),
]
