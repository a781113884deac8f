"""/api/cobots/… and /api/cobot-credentials/…"""

from rest_framework.routers import SimpleRouter

from hrc.cobots.api.views import CobotViewSet, CredentialsSecretViewSet

router = SimpleRouter()
router.register("cobots", CobotViewSet, basename="cobot")
router.register("cobot-credentials", CredentialsSecretViewSet, basename="cobot-credentials")

urlpatterns = router.urls
