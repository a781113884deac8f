"""The supervisor pages: /cases/, /cases/<id>/ and /incidents/ (the API's routes are api/urls.py)."""

from django.urls import path

from hrc.cases import views

app_name = "cases"

urlpatterns = [
    path("cases/", views.case_list, name="case-list"),
    path("cases/<int:pk>/", views.case_detail, name="case-detail"),
    path("incidents/", views.incident_list, name="incident-list"),
]
