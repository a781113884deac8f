// The tablet's copy of the live state: a snapshot, then deltas applied in each case's order.
//
// Case deltas are numbered per case (seq = the case's event number). One with
// seq <= the case's known seq is already in the state and is ignored; seq =
// known + 1 is applied; a later one is held until the missing ones arrive
// (the server's processes may deliver slightly out of order), and if they do
// not come, the socket asks for a new snapshot (see socket.ts). Every delta
// carries whole objects, so applying one twice changes nothing.

import type {
  CaseData,
  CaseStreamDelta,
  CellStopData,
  CobotData,
  CobotQueueData,
  CobotStateData,
  FloorCobot,
  IncidentData,
  LiveEvent,
  Snapshot,
  TimerData,
  UserData,
  WorkItemData,
} from "./events";
import { OPEN_CASE_STATUSES, OPEN_WORK_ITEM_STATES } from "../shared/choices";


export interface LiveState {
  organisation: number;
  cell: string;
  user: UserData;
  cases: Map<number, CaseData>;
  workItems: Map<number, WorkItemData>;
  incidents: Map<number, IncidentData>;
  // The armed timers, by timerKey: the case waits for each until its due_at.
  timers: Map<string, TimerData>;
  cobots: Map<number, CobotData>;
  // Every cobot of the organisation, with its cell, as of the snapshot.
  floor: Map<number, FloorCobot>;
  stop: CellStopData | null;
}

/** What became of an event: applied, ignored (old or not ours), or held for a missing seq. */
export type Outcome = "applied" | "ignored" | "held";

export class LiveStore {
  state: LiveState | null = null;
  private held = new Map<number, Map<number, CaseStreamDelta>>();
  // Cases that ended, with their last seq: late deltas of theirs are old, not holes.
  private ended = new Map<number, number>();
  private listeners: Array<(event: LiveEvent) => void> = [];
  // Held deltas that the last applied one let through, in order.
  private followers: CaseStreamDelta[] = [];

  subscribe(listener: (event: LiveEvent) => void): () => void {
    this.listeners.push(listener);
    return () => {
      this.listeners = this.listeners.filter((l) => l !== listener);
    };
  }

  /** Whether deltas wait for one that has not arrived. */
  hasHoles(): boolean {
    return this.held.size > 0;
  }

  apply(event: LiveEvent): Outcome {
    this.followers = [];
    const outcome = this.applyOne(event);
    if (outcome === "applied") {
      for (const applied of [event, ...this.followers]) this.listeners.forEach((listener) => listener(applied));
    }
    return outcome;
  }

  private applyOne(event: LiveEvent): Outcome {
    if (event.type === "snapshot") {
      this.applySnapshot(event);
      return "applied";
    }
    if (this.state === null || event.type === "refused") return "ignored";
    switch (event.type) {
      case "case":
      case "work-item":
      case "incident":
      case "timer":
        return this.applyCaseDelta(event);
      case "cobot-state":
        return this.applyStates(event.states);
      case "cobot-queue":
        return this.applyQueue(event.queue);
      case "cell-stop":
        return this.applyStop(event.stop);
    }
  }

  applySnapshot(snapshot: Snapshot): void {
    this.held.clear();
    this.ended.clear();
    this.state = {
      organisation: snapshot.organisation,
      cell: snapshot.cell,
      user: snapshot.user,
      cases: new Map(snapshot.cases.map((c) => [c.id, c])),
      workItems: new Map(snapshot.work_items.map((w) => [w.id, w])),
      incidents: new Map(snapshot.incidents.map((i) => [i.id, i])),
      timers: new Map(snapshot.timers.map((t) => [timerKey(t), t])),
      cobots: new Map(snapshot.cobots.map((c) => [c.id, c])),
      floor: new Map(snapshot.floor.map((c) => [c.id, c])),
      stop: snapshot.stop,
    };
  }

  private knownSeq(caseId: number): number | null {
    const known = this.state?.cases.get(caseId);
    if (known) return known.seq;
    return this.ended.get(caseId) ?? null;
  }

  private applyCaseDelta(delta: CaseStreamDelta): Outcome {
    const known = this.knownSeq(delta.case);
    if (known !== null && delta.seq <= known) return "ignored";
    const next = known === null ? 1 : known + 1;
    if (delta.seq !== next || (known === null && delta.type !== "case")) {
      let waiting = this.held.get(delta.case);
      if (!waiting) this.held.set(delta.case, (waiting = new Map<number, CaseStreamDelta>()));
      waiting.set(delta.seq, delta);
      return "held";
    }
    this.applyInOrder(delta);
    // The ones that waited for this one.
    const waiting = this.held.get(delta.case);
    let seq = delta.seq + 1;
    while (waiting?.has(seq)) {
      const following = waiting.get(seq)!;
      waiting.delete(seq);
      this.applyInOrder(following);
      this.followers.push(following);
      seq += 1;
    }
    if (waiting && waiting.size === 0) this.held.delete(delta.case);
    return "applied";
  }

  private applyInOrder(delta: CaseStreamDelta): void {
    const state = this.state!;
    const current = state.cases.get(delta.case);
    if (delta.type === "case") {
      if (OPEN_CASE_STATUSES.has(delta.data.status)) {
        state.cases.set(delta.case, { ...delta.data, seq: delta.seq });
      } else {
        this.endCase(delta.case, delta.seq);
      }
      return;
    }
    if (current) current.seq = delta.seq;
    else if (this.ended.has(delta.case)) this.ended.set(delta.case, delta.seq);
    if (delta.type === "work-item") {
      const shown = OPEN_WORK_ITEM_STATES.has(delta.item.state) || delta.item.in_area;
      if (shown) state.workItems.set(delta.item.id, delta.item);
      else state.workItems.delete(delta.item.id);
    } else if (delta.type === "timer") {
      // Armed: shown until it fires or is disarmed (its transition no longer enabled).
      if (delta.event === "timer-armed") state.timers.set(timerKey(delta.timer), delta.timer);
      else state.timers.delete(timerKey(delta.timer));
    } else if (delta.incident.resolution === "") {
      state.incidents.set(delta.incident.id, delta.incident);
    } else {
      state.incidents.delete(delta.incident.id);
    }
  }

  private endCase(caseId: number, seq: number): void {
    const state = this.state!;
    state.cases.delete(caseId);
    this.ended.set(caseId, seq);
    for (const [id, item] of state.workItems) if (item.case === caseId) state.workItems.delete(id);
    for (const [id, incident] of state.incidents) {
      if (incident.case === caseId) state.incidents.delete(id);
    }
    for (const [key, timer] of state.timers) if (timer.case === caseId) state.timers.delete(key);
  }

  private applyStates(states: CobotStateData[]): Outcome {
    let changed = false;
    for (const data of states) {
      const cobot = this.state!.cobots.get(data.cobot);
      if (!cobot || (cobot.state && cobot.state.at > data.at)) continue;
      cobot.state = data;
      changed = true;
    }
    return changed ? "applied" : "ignored";
  }

  private applyQueue(queue: CobotQueueData): Outcome {
    const cobot = this.state!.cobots.get(queue.cobot);
    if (!cobot || cobot.queue.at > queue.at) return "ignored";
    cobot.queue = queue;
    return "applied";
  }

  private applyStop(stop: CellStopData): Outcome {
    const state = this.state!;
    const holding = stop.resumed_at === null;
    for (const id of stop.cobots) {
      const cobot = state.cobots.get(id);
      if (cobot) cobot.stopped = holding;
    }
    if (holding && (stop.cell === state.cell || stop.cell === "")) {
      if (!state.stop || state.stop.cell !== state.cell || stop.cell === state.cell) state.stop = stop;
    } else if (!holding && state.stop?.id === stop.id) {
      state.stop = null;
    }
    return "applied";
  }

  /** The held deltas are given up on (a new snapshot is on its way). */
  dropHeld(): void {
    this.held.clear();
  }
}

/** A case has at most one armed timer per timer transition. */
export function timerKey(timer: TimerData): string {
  return `${timer.case}:${timer.transition}`;
}

/** The armed timers soonest due first, as the snapshot lists them. */
export function timersByDue(timers: Iterable<TimerData>): TimerData[] {
  return [...timers].sort(
    (a, b) =>
      Date.parse(a.due_at) - Date.parse(b.due_at) ||
      a.case - b.case ||
      (a.transition < b.transition ? -1 : a.transition > b.transition ? 1 : 0),
  );
}

/** The state in the snapshot's shape, sorted by id: what the event-stream test compares. */
export function asSnapshot(state: LiveState): Omit<Snapshot, "type"> {
  const byId = <T extends { id: number }>(values: Iterable<T>): T[] =>
    [...values].sort((a, b) => a.id - b.id);
  return {
    organisation: state.organisation,
    cell: state.cell,
    user: state.user,
    cases: byId(state.cases.values()),
    work_items: byId(state.workItems.values()),
    incidents: byId(state.incidents.values()),
    timers: timersByDue(state.timers.values()),
    cobots: byId(state.cobots.values()),
    floor: byId(state.floor.values()),
    stop: state.stop,
  };
}
