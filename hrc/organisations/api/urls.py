"""/api/organisations/ and /api/organisations/me/."""

from rest_framework.routers import SimpleRouter

from hrc.organisations.api.views import OrganisationViewSet

router = SimpleRouter()
router.register("organisations", OrganisationViewSet, basename="organisation")

urlpatterns = router.urls
