import type { CaseDelta, Snapshot, TimerData, TimerDelta, WorkItemData, WorkItemDelta } from "../../src/live/events";

export function snapshot(overrides: Partial<Snapshot> = {}): Snapshot {
  return {
    type: "snapshot",
    organisation: 1,
    cell: "",
    user: { id: 7, username: "olivia", role: "operator", teams: [3] },
    cases: [{ id: 10, seq: 2, status: "running", name: "Hand-over", cobots: [5] }],
    work_items: [item({ id: 100 })],
    incidents: [],
    timers: [],
    cobots: [
      {
        id: 5,
        name: "cobot1",
        cell: "",
        stopped: false,
        state: null,
        queue: { cobot: 5, at: 1, queue_length: 0, current: null, waiting_for: "" },
      },
    ],
    floor: [{ id: 5, name: "cobot1", cell: "" }],
    stop: null,
    ...overrides,
  };
}

export function item(overrides: Partial<WorkItemData> = {}): WorkItemData {
  return {
    id: 100,
    case: 10,
    task: "count",
    label: "Count the parts",
    actor: "o",
    kind: "operator",
    state: "offered",
    instructions: "",
    team: null,
    cobot: null,
    candidates: [7],
    claimed_by: null,
    offered_at: "2026-01-01T00:00:00+00:00",
    started_at: null,
    in_area: false,
    ...overrides,
  };
}

export function itemDelta(seq: number, overrides: Partial<WorkItemData> = {}, event = "task-offered"): WorkItemDelta {
  return { type: "work-item", case: 10, seq, event, item: item(overrides) };
}

export function caseDelta(caseId: number, seq: number, status: string, event: string): CaseDelta {
  return {
    type: "case",
    case: caseId,
    seq,
    event,
    data: { id: caseId, seq, status, name: "Hand-over", cobots: [5] },
  };
}

export function timer(overrides: Partial<TimerData> = {}): TimerData {
  return { case: 10, transition: "late", label: "Too late", due_at: "2026-01-01T10:20:30+00:00", ...overrides };
}

export function timerDelta(seq: number, event: string, overrides: Partial<TimerData> = {}): TimerDelta {
  return { type: "timer", case: 10, seq, event, timer: timer(overrides) };
}
