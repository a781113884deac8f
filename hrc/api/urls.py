"""Collects each app's API routes under /api/."""

from django.urls import include, path

urlpatterns = [
    path("", include("hrc.organisations.api.urls")),
    path("", include("hrc.patterns.api.urls")),
    path("", include("hrc.cobots.api.urls")),
    path("", include("hrc.cases.api.urls")),
    path("", include("hrc.live.api.urls")),
    path("", include("hrc.analytics.api.urls")),
]
