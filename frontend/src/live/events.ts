// What goes over the tablets' WebSocket: the mirror of hrc/live/events.py, field for field
// (tests/live/test_events_mirror.py compares the two). The protocol is explained there; a
// frame is one LiveEvent or an array of them (the deltas of one commit, in order).

export interface CaseData {
  id: number;
  seq: number;
  status: string;
  name: string;
  cobots: number[];
}

export interface WorkItemData {
  id: number;
  case: number;
  task: string;
  label: string;
  actor: string;
  kind: string;
  state: string;
  instructions: string;
  team: number | null;
  cobot: number | null;
  candidates: number[];
  claimed_by: number | null;
  offered_at: string;
  started_at: string | null;
  // A cancelled operator task whose operator may still be in its shared area (a cobot waits).
  in_area: boolean;
}

export interface IncidentData {
  id: number;
  case: number;
  work_item: number | null;
  kind: string;
  message: string;
  resolution: string;
}

export interface CaseDelta {
  type: "case";
  case: number;
  seq: number;
  event: string;
  data: CaseData;
}

export interface WorkItemDelta {
  type: "work-item";
  case: number;
  seq: number;
  event: string;
  item: WorkItemData;
}

export interface IncidentDelta {
  type: "incident";
  case: number;
  seq: number;
  event: string;
  incident: IncidentData;
}

/** An armed timer: its case waits for it until due_at (ISO 8601). */
export interface TimerData {
  case: number;
  transition: string;
  label: string;
  due_at: string;
}

/** A timer was armed (shown from now), or fired or was disarmed (dropped). */
export interface TimerDelta {
  type: "timer";
  case: number;
  seq: number;
  event: string;
  timer: TimerData;
}

export interface CobotStateData {
  cobot: number;
  at: number;
  reachable: boolean;
  robot_mode: string;
  safety_mode: string;
  program_state: string;
  program: string;
  joints: number[];
  display: string;
  display_at: number;
  error: string;
}

export interface CobotStateDelta {
  type: "cobot-state";
  states: CobotStateData[];
}

export interface CurrentStep {
  case: number;
  work_item: number;
  task: string;
  label: string;
  kind: string;
  step: number | null;
  attempt: number;
}

export interface CobotQueueData {
  cobot: number;
  at: number;
  queue_length: number;
  current: CurrentStep | null;
  waiting_for: string;
}

export interface CobotQueueDelta {
  type: "cobot-queue";
  queue: CobotQueueData;
}

export interface CobotData {
  id: number;
  name: string;
  cell: string;
  stopped: boolean;
  state: CobotStateData | null;
  queue: CobotQueueData;
}

/** Where one of the organisation's cobots stands: how a cell's tablet names another cell. */
export interface FloorCobot {
  id: number;
  name: string;
  cell: string;
}

export interface CellStopData {
  id: number;
  cell: string;
  at: number;
  stopped_by: string;
  stopped_at: string;
  resumed_by: string;
  resumed_at: string | null;
  cobots: number[];
  problems: Record<string, string>;
}

export interface CellStopDelta {
  type: "cell-stop";
  stop: CellStopData;
}

export interface UserData {
  id: number;
  username: string;
  role: string;
  teams: number[];
}

export interface Snapshot {
  type: "snapshot";
  organisation: number;
  cell: string;
  user: UserData;
  cases: CaseData[];
  work_items: WorkItemData[];
  incidents: IncidentData[];
  timers: TimerData[]; // the armed timers of the open cases, soonest due first
  cobots: CobotData[];
  floor: FloorCobot[];
  stop: CellStopData | null;
}

export interface Refused {
  type: "refused";
  reason: string;
}

export type LiveEvent =
  | Snapshot
  | CaseDelta
  | WorkItemDelta
  | IncidentDelta
  | TimerDelta
  | CobotStateDelta
  | CobotQueueDelta
  | CellStopDelta
  | Refused;

/** Numbered per case; a tablet checks these for holes. */
export type CaseStreamDelta = CaseDelta | WorkItemDelta | IncidentDelta | TimerDelta;
export const CASE_DELTA_TYPES: ReadonlySet<string> = new Set(["case", "work-item", "incident", "timer"]);
