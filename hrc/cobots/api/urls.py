"""/api/cobots/… and /api/cobot-credentials/…"""

from hrc.api.routers import IdRouter
from hrc.cobots.api.views import CobotViewSet, CredentialsSecretViewSet

router = IdRouter()
router.register("cobots", CobotViewSet, basename="cobot")
router.register("cobot-credentials", CredentialsSecretViewSet, basename="cobot-credentials")

urlpatterns = router.urls
