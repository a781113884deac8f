"""The editor's pages: /patterns/, /patterns/new/ and /patterns/<id>/edit/ (the API's routes are api/urls.py)."""

from django.urls import path

from hrc.patterns import views

app_name = "patterns"

urlpatterns = [
    path("patterns/", views.pattern_list, name="list"),
    path("patterns/new/", views.pattern_new, name="new"),
    path("patterns/<int:pk>/edit/", views.pattern_edit, name="edit"),
    path("patterns/<int:pk>/archive/", views.pattern_archive, name="archive"),
]
