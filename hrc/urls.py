"""URL map: a start page, admin, the REST API under /api/, its OpenAPI schema and browsable docs."""

from django.contrib import admin
from django.urls import include, path
from django.views.generic import TemplateView
from drf_spectacular.views import SpectacularAPIView, SpectacularSwaggerView
from rest_framework.authtoken.views import obtain_auth_token

urlpatterns = [
    path("", TemplateView.as_view(template_name="home.html"), name="home"),
    path("admin/", admin.site.urls),
    # The operators' tablets (hrc.live).
    path("", include("hrc.live.urls")),
    path("", include("hrc.cases.urls")),  # the supervisor pages: /cases/, /incidents/
    path("", include("hrc.patterns.urls")),  # the pattern editor: /patterns/
    path("", include("hrc.analytics.urls")),
    path(
        "", include("hrc.cobots.urls")
    ),  # the cobot pages: /cobots/, control for engineers  # /analytics/: figures per version, Gantt per case
    path("", include("hrc.organisations.urls")),  # /organisation/: people, teams, cells
    # Sign-in, sign-out and password change for the tablets and the editor.
    path("accounts/", include("django.contrib.auth.urls")),
    path("api/schema/", SpectacularAPIView.as_view(), name="api-schema"),
    path("api/docs/", SpectacularSwaggerView.as_view(url_name="api-schema"), name="api-docs"),
    # Machines trade a username and password for a token once, then send `Authorization: Token …`.
    path("api/token/", obtain_auth_token, name="api-token"),
    path("api/", include("hrc.api.urls")),
    # Sign-in for the browsable API (session auth), so a person can try it from the browser.
    path("api/auth/", include("rest_framework.urls")),
]
