"""URL map: a start page, admin, the REST API under /api/, its OpenAPI schema and browsable docs."""

from django.contrib import admin
from django.urls import include, path
from django.views.generic import TemplateView
from drf_spectacular.views import SpectacularAPIView, SpectacularSwaggerView

urlpatterns = [
    path("", TemplateView.as_view(template_name="home.html"), name="home"),
    path("admin/", admin.site.urls),
    path("api/schema/", SpectacularAPIView.as_view(), name="api-schema"),
    path("api/docs/", SpectacularSwaggerView.as_view(url_name="api-schema"), name="api-docs"),
    path("api/", include("hrc.api.urls")),
    # Sign-in for the browsable API (session auth), so a person can try it from the browser.
    path("api/auth/", include("rest_framework.urls")),
]
