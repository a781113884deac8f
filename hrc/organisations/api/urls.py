"""/api/organisations/ (with me/), and the administration: members/, teams/, cells/, admin-records/."""

from hrc.api.routers import IdRouter
from hrc.organisations.api.admin_views import (
    AdminRecordViewSet,
    CellViewSet,
    MemberViewSet,
    TeamViewSet,
)
from hrc.organisations.api.views import OrganisationViewSet

router = IdRouter()
router.register("organisations", OrganisationViewSet, basename="organisation")
router.register("members", MemberViewSet, basename="member")
router.register("teams", TeamViewSet, basename="team")
router.register("cells", CellViewSet, basename="cell")
router.register("admin-records", AdminRecordViewSet, basename="admin-record")

urlpatterns = router.urls
