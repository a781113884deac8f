"""POST /api/cells/stop/ and /api/cells/resume/: a tablet's STOP and its confirmed resume.

Any member of the organisation may stop its cells and resume them (operators
above all: they stand at the cell). A non-member is told the organisation is
not theirs (400), as target_organisation does. A cell the organisation does
not have, or none, is refused (400 naming `cell`): nothing is stopped, nothing written.
"""

from typing import Any

from drf_spectacular.utils import extend_schema
from rest_framework import status
from rest_framework.request import Request
from rest_framework.response import Response
from rest_framework.views import APIView

from hrc.api.exceptions import Rejected
from hrc.cases.api.serializers import RefusalSerializer
from hrc.cobots import stops
from hrc.live import payloads, selectors
from hrc.live.api.serializers import (
    CellRequestSerializer,
    CellStopSerializer,
    ResumeRequestSerializer,
)
from hrc.organisations.models import Organisation

REFUSALS = {400: RefusalSerializer, 409: RefusalSerializer}


class StopCellView(APIView):
    @extend_schema(request=CellRequestSerializer, responses={201: CellStopSerializer, **REFUSALS})
    def post(self, request: Request) -> Response:
        """Pauses every cobot of the cell and holds their queues until a confirmed resume.

        A convenience, not a safety function. 201 with the STOP; 200 with the
        one already holding the cell.
        """
        body = CellRequestSerializer(data=request.data)
        body.is_valid(raise_exception=True)
        organisation = _organisation(request, body.validated_data.get("organisation"))
        cell = _cell(organisation, body.validated_data["cell"])
        before = selectors.active_stop(organisation.pk, cell)
        stop = stops.stop_cell(organisation, cell, by=request.user)  # type: ignore[arg-type]
        code = status.HTTP_200_OK if before and before["id"] == stop.pk else status.HTTP_201_CREATED
        return Response(payloads.stop_data(stop), status=code)


class ResumeCellView(APIView):
    @extend_schema(request=ResumeRequestSerializer, responses={200: CellStopSerializer, **REFUSALS})
    def post(self, request: Request) -> Response:
        """Ends the cell's STOP (with confirm: true): queues go on, paused programs restart,
        except where an operator's interruption or a safety stop still holds a cobot."""
        body = ResumeRequestSerializer(data=request.data)
        body.is_valid(raise_exception=True)
        organisation = _organisation(request, body.validated_data.get("organisation"))
        cell = _cell(organisation, body.validated_data["cell"])
        stop = stops.resume_cell(
            organisation,
            cell,
            by=request.user,  # type: ignore[arg-type]
            confirmed=body.validated_data["confirm"],
        )
        return Response(payloads.stop_data(stop))


def _organisation(request: Request, requested: Any) -> Organisation:
    access = selectors.access_of(request.user, requested)
    if access is None:
        what = f"organisation {requested}" if requested is not None else "any organisation"
        raise Rejected({"detail": f"You are not a member of {what}."})
    return Organisation.objects.get(pk=access.organisation_id)


def _cell(organisation: Organisation, cell: str) -> str:
    if not cell:
        # Never "every cobot": a STOP names the cell it is for, so no empty value can ever
        # reach cobots beyond the one cell of the one organisation.
        message = f"Name the cell to stop or resume: one of {organisation.name}'s cells."
        raise Rejected({"detail": message, "fields": {"cell": [message]}})
    if not selectors.is_cell(organisation.pk, cell):
        message = f"There is no cell {cell!r} in {organisation.name}."
        raise Rejected({"detail": message, "fields": {"cell": [message]}})
    return cell
