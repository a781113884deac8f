"""The cobot pages: /cobots/, /cobots/<id>/, new/, <id>/edit/, credentials/ and devices/ (the API's
routes are api/urls.py)."""

from django.urls import path

from hrc.cobots import views

app_name = "cobots"

urlpatterns = [
    path("cobots/", views.cobot_list, name="cobot-list"),
    path("cobots/new/", views.cobot_new, name="cobot-new"),
    path("cobots/credentials/", views.credentials_secrets, name="credentials"),
    path("cobots/devices/", views.device_list, name="device-list"),
    path("cobots/devices/new/", views.device_new, name="device-new"),
    path("cobots/devices/<int:pk>/edit/", views.device_edit, name="device-edit"),
    path("cobots/<int:pk>/", views.cobot_detail, name="cobot-detail"),
    path("cobots/<int:pk>/edit/", views.cobot_edit, name="cobot-edit"),
]
