"""/api/cobots/…"""

from hrc.api.routers import IdRouter
from hrc.cobots.api.views import CobotViewSet

router = IdRouter()
router.register("cobots", CobotViewSet, basename="cobot")

urlpatterns = router.urls
