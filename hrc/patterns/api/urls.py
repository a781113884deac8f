"""/api/patterns/… and /api/pattern-versions/…"""

from rest_framework.routers import SimpleRouter

from hrc.patterns.api.views import PatternVersionViewSet, PatternViewSet

router = SimpleRouter()
router.register("patterns", PatternViewSet, basename="pattern")
router.register("pattern-versions", PatternVersionViewSet, basename="pattern-version")

urlpatterns = router.urls
