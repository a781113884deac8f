"""The organisation's administration pages: /organisation/people/, teams/, cells/."""

from django.urls import path

from hrc.organisations import views

app_name = "organisation"

urlpatterns = [
    path("organisation/people/", views.people, name="people"),
    path("organisation/people/<int:pk>/", views.person, name="person"),
    path(
        "organisation/people/<int:pk>/deactivate/",
        views.deactivate_person,
        name="person-deactivate",
    ),
    path(
        "organisation/people/<int:pk>/reset-password/",
        views.reset_password,
        name="person-reset-password",
    ),
    path("organisation/join/<str:uidb64>/<str:token>/", views.join, name="join"),
    path("organisation/teams/", views.teams, name="teams"),
    path("organisation/teams/<int:pk>/", views.team, name="team"),
    path("organisation/cells/", views.cells, name="cells"),
    path("organisation/cells/<int:pk>/", views.cell, name="cell"),
]
