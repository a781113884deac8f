"""Collects each app's API routes under /api/."""

from django.urls import include, path

urlpatterns = [
    path("", include("hrc.patterns.api.urls")),
]
