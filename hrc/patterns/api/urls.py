"""/api/patterns/… and /api/pattern-versions/…"""

from hrc.api.routers import IdRouter
from hrc.patterns.api.views import PatternVersionViewSet, PatternViewSet

router = IdRouter()
router.register("patterns", PatternViewSet, basename="pattern")
router.register("pattern-versions", PatternVersionViewSet, basename="pattern-version")

urlpatterns = router.urls
