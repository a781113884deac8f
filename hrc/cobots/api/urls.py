"""/api/cobots/…, /api/devices/… and /api/cobot-credentials/…"""

from hrc.api.routers import IdRouter
from hrc.cobots.api.views import CobotViewSet, CredentialsSecretViewSet, DeviceViewSet

router = IdRouter()
router.register("cobots", CobotViewSet, basename="cobot")
router.register("devices", DeviceViewSet, basename="device")
router.register("cobot-credentials", CredentialsSecretViewSet, basename="cobot-credentials")

urlpatterns = router.urls
