"""URL map: the start page, admin, the REST API under /api/, its OpenAPI schema and docs."""

from django.contrib import admin
from django.urls import include, path, re_path
from drf_spectacular.views import (
    SpectacularAPIView,
    SpectacularRedocView,
    SpectacularSwaggerSplitView,
)

from hrc import home, navigation
from hrc.api.views import TokenView, api_not_found
from hrc.middleware import content_security_policy

urlpatterns = [
    # Sends each role to its place: operators to their tablet (also after sign-in).
    path("", home.home, name="home"),
    path("organisation/switch/", navigation.switch_organisation, name="switch-organisation"),
    path("admin/", admin.site.urls),
    # The operators' tablets (hrc.live).
    path("", include("hrc.live.urls")),
    path("", include("hrc.cases.urls")),  # the supervisor pages: /cases/, /incidents/
    path("", include("hrc.patterns.urls")),  # the pattern editor: /patterns/
    # /analytics/: figures per version, Gantt per case
    path("", include("hrc.analytics.urls")),
    path("", include("hrc.cobots.urls")),  # the cobot pages: /cobots/, control for engineers
    path("", include("hrc.organisations.urls")),  # /organisation/: people, teams, cells
    # Sign-in, sign-out and password change for the tablets and the editor.
    path("accounts/", include("django.contrib.auth.urls")),
    path("api/schema/", SpectacularAPIView.as_view(), name="api-schema"),
    # Swagger UI and ReDoc come from the project's static files (drf-spectacular-sidecar),
    # so they work on a plant network with no way out. The split view serves Swagger UI's
    # start-up script at ?script, not inline: the Content-Security-Policy refuses inline code.
    path(
        "api/docs/",
        SpectacularSwaggerSplitView.as_view(
            url_name="api-schema", template_name="api/swagger_ui.html"
        ),
        name="api-docs",
    ),
    # ReDoc's bundle writes its styles into <style> elements as it draws (styled-components)
    # and builds its search index in a worker it makes from a blob: so this page admits
    # inline styles and blob: workers; its scripts stay the site's own files only.
    path(
        "api/redoc/",
        content_security_policy(
            style_src=["'self'", "'unsafe-inline'"], worker_src=["'self'", "blob:"]
        )(SpectacularRedocView.as_view(url_name="api-schema", template_name="api/redoc.html")),
        name="api-redoc",
    ),
    # Machines trade a username and password for a key, then send `Authorization: Token …`.
    path("api/token/", TokenView.as_view(), name="api-token"),
    # Sign-in for the browsable API (session auth), so a person can try it from the browser.
    path("api/auth/", include("rest_framework.urls")),
    path("api/", include("hrc.api.urls")),
    # Last: any other address under /api/ answers a JSON 404, not an HTML page.
    re_path(r"^api/", api_not_found),
]
