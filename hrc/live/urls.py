"""Pages of the live layer: the operator tablet."""

from django.urls import path, re_path

from hrc.live import views

urlpatterns = [
    path("tablet/", views.tablet, name="tablet"),
    re_path(r"^tablet/(?P<cell>[A-Za-z0-9_-]{1,50})/$", views.tablet, name="tablet-cell"),
    re_path(
        r"^tablet/(?P<cell>[A-Za-z0-9_-]{1,50})/start/(?P<version>[0-9]{1,18})/$",
        views.start_cycle,
        name="tablet-start",
    ),
]
