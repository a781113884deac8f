"""/api/cases/…, /api/work-items/…, /api/incidents/…, /api/jobs/…, /api/messages/ and
/api/pattern-versions/{id}/actor-mapping/ (a version's setting that belongs to running it)."""

from django.urls import path

from hrc.api.routers import IdRouter
from hrc.cases.api.views import (
    ActorMappingView,
    CaseViewSet,
    IncidentViewSet,
    JobViewSet,
    MessageViewSet,
    WorkItemViewSet,
)

router = IdRouter()
router.register("cases", CaseViewSet, basename="case")
router.register("work-items", WorkItemViewSet, basename="work-item")
router.register("incidents", IncidentViewSet, basename="incident")
router.register("jobs", JobViewSet, basename="job")
router.register("messages", MessageViewSet, basename="message")

urlpatterns = [
    *router.urls,
    path(
        "pattern-versions/<int:pk>/actor-mapping/",
        ActorMappingView.as_view(),
        name="pattern-version-actor-mapping",
    ),
]
