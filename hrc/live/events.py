"""What goes over the tablets' WebSocket: one TypedDict per event type, each with a Literal `type`.

Mirrored exactly in frontend/src/live/events.ts (a test compares the two).

The protocol. On connect the server sends a `snapshot`; after it, deltas. A
frame holds one event (a JSON object) or several in order (a JSON array: the
deltas of one commit).
Case deltas (`case`, `work-item`, `incident`) are numbered per case: their
`seq` is the case's event number (CaseEvent.seq), so each case is a stream
1, 2, 3… with no holes. A tablet applies seq = known + 1, ignores seq ≤ known
(already in its snapshot: the server joins the groups before it reads the
snapshot, so a change may arrive twice, never not at all), and on a hole
waits briefly for the late one, then asks for a new snapshot
(`{"type": "resync"}` from the client). Every delta carries the whole
object it changes, so applying one twice changes nothing.

Cobot deltas (`cobot-state` from the gateways, `cobot-queue` from the
database) and `cell-stop` carry whole state too; the newest (`at`) wins,
and a lost one is replaced by the next. `cobot-state` is coalesced per
tablet: at most 10 a second.
"""

from __future__ import annotations

from typing import Literal, TypedDict

# Case deltas ---------------------------------------------------------------------------


class CaseData(TypedDict):
    id: int
    seq: int  # the case's latest event number the data reflects
    status: str  # hrc.cases.choices.CaseStatus
    name: str  # the pattern's name
    cobots: list[int]  # the cobots its actors are mapped to


class WorkItemData(TypedDict):
    id: int
    case: int
    task: str
    label: str
    actor: str
    kind: str  # operator | step | device
    state: str  # hrc.cases.choices.WorkItemState
    instructions: str
    team: int | None
    cobot: int | None
    candidates: list[int]  # user ids the actor is mapped to (besides the team's members)
    claimed_by: int | None
    offered_at: str
    started_at: str | None
    # A cancelled operator task whose operator may still be in its shared area: a cobot stays
    # paused or slowed until they (or a supervisor) say they have left (POST .../left-area/).
    in_area: bool


class IncidentData(TypedDict):
    id: int
    case: int
    work_item: int | None
    kind: str
    message: str
    resolution: str  # "" while open


class CaseDelta(TypedDict):
    """A case started, was suspended or resumed, ended, or fired something no tablet shows."""

    type: Literal["case"]
    case: int
    seq: int
    event: str  # hrc.cases.choices.EventType
    data: CaseData


class WorkItemDelta(TypedDict):
    """A work item was offered, claimed, started, completed, withdrawn…: the item as it is now."""

    type: Literal["work-item"]
    case: int
    seq: int
    event: str
    item: WorkItemData


class TimerData(TypedDict):
    """An armed timer: its case waits for it until due_at (ISO 8601)."""

    case: int
    transition: str
    label: str
    due_at: str


class TimerDelta(TypedDict):
    """A timer was armed (shown from now), or fired or was disarmed (dropped)."""

    type: Literal["timer"]
    case: int
    seq: int
    event: str  # timer-armed, timer-fired, timer-disarmed
    timer: TimerData


class IncidentDelta(TypedDict):
    type: Literal["incident"]
    case: int
    seq: int
    event: str
    incident: IncidentData


# Cobots and the cell -------------------------------------------------------------------


class CobotStateData(TypedDict):
    """What the cobot's gateway reports (hrc.live.monitor)."""

    cobot: int
    at: float  # seconds since the epoch, when the monitor saw it
    reachable: bool
    robot_mode: str
    safety_mode: str
    program_state: str
    program: str
    joints: list[float]  # radians, base to wrist 3
    display: str  # the text on the cell's display device
    display_at: float  # when that text appeared (seconds since the epoch): a message's time
    error: str  # why the gateway cannot be reached, or its last refusal


class CobotStateDelta(TypedDict):
    """The latest state of each cobot that changed, at most 10 of these a second per tablet."""

    type: Literal["cobot-state"]
    states: list[CobotStateData]


class CurrentStep(TypedDict):
    case: int
    work_item: int
    task: str
    label: str
    kind: str  # step | device
    step: int | None  # the program's step number
    attempt: int


class CobotQueueData(TypedDict):
    """The cobot's work as the database has it: what it runs now and how many wait."""

    cobot: int
    at: float
    queue_length: int  # queued and running jobs
    current: CurrentStep | None
    waiting_for: str  # why its next job has not started ("" when none waits)


class CobotQueueDelta(TypedDict):
    type: Literal["cobot-queue"]
    queue: CobotQueueData


class CobotData(TypedDict):
    id: int
    name: str
    cell: str
    stopped: bool  # held by a tablet's STOP
    state: CobotStateData | None  # None until the monitor has reported
    queue: CobotQueueData


class FloorCobot(TypedDict):
    """Where one of the organisation's cobots stands: how a cell's tablet names another cell."""

    id: int
    name: str
    cell: str


class CellStopData(TypedDict):
    id: int
    cell: str  # "" for the whole organisation
    at: float
    stopped_by: str
    stopped_at: str
    resumed_by: str
    resumed_at: str | None
    cobots: list[int]
    problems: dict[str, str]  # cobot id -> why it could not be paused or resumed


class CellStopDelta(TypedDict):
    """A tablet stopped the cell, or someone confirmed resuming it."""

    type: Literal["cell-stop"]
    stop: CellStopData


# The snapshot --------------------------------------------------------------------------


class UserData(TypedDict):
    id: int
    username: str
    role: str
    teams: list[int]


class Snapshot(TypedDict):
    type: Literal["snapshot"]
    organisation: int
    cell: str
    user: UserData
    cases: list[CaseData]
    work_items: list[WorkItemData]
    incidents: list[IncidentData]
    timers: list[TimerData]  # the armed timers of the open cases, soonest due first
    cobots: list[CobotData]  # the tablet's cell's cobots (every one for the whole floor)
    floor: list[FloorCobot]  # every cobot of the organisation, by id
    stop: CellStopData | None  # the cell's STOP while it holds


class Refused(TypedDict):
    """Sent before the server closes the socket: why (no access, bad request)."""

    type: Literal["refused"]
    reason: str


LiveEvent = (
    Snapshot
    | CaseDelta
    | WorkItemDelta
    | IncidentDelta
    | TimerDelta
    | CobotStateDelta
    | CobotQueueDelta
    | CellStopDelta
    | Refused
)
# Numbered per case; a tablet checks these for holes.
CASE_DELTA_TYPES = frozenset({"case", "work-item", "incident", "timer"})
