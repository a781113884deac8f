"""/api/cobots/…"""

from rest_framework.routers import SimpleRouter

from hrc.cobots.api.views import CobotViewSet

router = SimpleRouter()
router.register("cobots", CobotViewSet, basename="cobot")

urlpatterns = router.urls
