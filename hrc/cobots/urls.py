"""The cobot pages: /cobots/ and /cobots/<id>/ (the API's routes are api/urls.py)."""

from django.urls import path

from hrc.cobots import views

app_name = "cobots"

urlpatterns = [
    path("cobots/", views.cobot_list, name="cobot-list"),
    path("cobots/<int:pk>/", views.cobot_detail, name="cobot-detail"),
]
