"""Collects each app's API routes under /api/, and the root that lists them."""

from django.urls import include, path

from hrc.api.views import ApiRootView

urlpatterns = [
    path("", ApiRootView.as_view(), name="api-root"),
    path("", include("hrc.organisations.api.urls")),
    path("", include("hrc.patterns.api.urls")),
    path("", include("hrc.cobots.api.urls")),
    path("", include("hrc.cases.api.urls")),
    path("", include("hrc.live.api.urls")),
    path("", include("hrc.analytics.api.urls")),
]
