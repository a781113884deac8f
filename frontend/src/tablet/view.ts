// What the tablet shows, derived from the live state: pure functions, tested without a page.

import type { CobotData, WorkItemData } from "../live/events";
import type { LiveState } from "../live/store";

/** Operator tasks that are the user's: claimed or started by them, or offered to them by name. */
export function myTasks(state: LiveState): WorkItemData[] {
  const me = state.user.id;
  return sorted(
    [...state.workItems.values()].filter(
      (item) =>
        item.kind === "operator" &&
        (item.claimed_by === me ||
          (item.claimed_by === null && item.state === "offered" && item.candidates.includes(me))),
    ),
  );
}

/** Open operator tasks of the user's teams that nobody has taken: theirs to claim. */
export function teamTasks(state: LiveState): WorkItemData[] {
  const me = state.user.id;
  const teams = new Set(state.user.teams);
  return sorted(
    [...state.workItems.values()].filter(
      (item) =>
        item.kind === "operator" &&
        item.state === "offered" &&
        item.claimed_by === null &&
        item.team !== null &&
        teams.has(item.team) &&
        !item.candidates.includes(me),
    ),
  );
}

function sorted(items: WorkItemData[]): WorkItemData[] {
  return items.sort((a, b) => a.offered_at.localeCompare(b.offered_at) || a.id - b.id);
}

/** The cobots an operator task works with: those of its case, known to this tablet. */
export function cobotsOf(state: LiveState, item: WorkItemData): CobotData[] {
  const ids = state.cases.get(item.case)?.cobots ?? [];
  return ids.map((id) => state.cobots.get(id)).filter((c): c is CobotData => c !== undefined);
}

/** One line: what the cobot is doing right now, or waiting for. */
export function activity(cobot: CobotData): string {
  const state = cobot.state;
  if (cobot.stopped) return "held by STOP";
  if (state && !state.reachable) return `unreachable${state.error ? `: ${state.error}` : ""}`;
  if (state && !["SAFETY_MODE_NORMAL", "SAFETY_MODE_REDUCED"].includes(state.safety_mode)) {
    return `${humanSafety(state.safety_mode)}: clear it at the robot`;
  }
  const current = cobot.queue.current;
  if (current) {
    const step = current.step !== null ? ` (step ${current.step})` : "";
    const paused = state?.program_state === "Paused" ? ", paused" : "";
    return `${current.label || current.task}${step}, case ${current.case}${paused}`;
  }
  if (cobot.queue.waiting_for) return `waiting: ${cobot.queue.waiting_for}`;
  return cobot.queue.queue_length ? `${cobot.queue.queue_length} queued` : "idle";
}

export function humanSafety(mode: string): string {
  return mode.replace(/^SAFETY_MODE_/, "").replace(/_/g, " ").toLowerCase();
}

/** What the task's button does next: claim, start, complete; null when nothing. */
export function nextAction(state: LiveState, item: WorkItemData): "claim" | "start" | "complete" | null {
  const me = state.user.id;
  if (item.state === "running") return item.claimed_by === me ? "complete" : null;
  if (item.state === "claimed") return item.claimed_by === me ? "start" : null;
  if (item.state === "offered") return item.candidates.includes(me) ? "start" : "claim";
  return null;
}

/** Joint angles in degrees, for the panel. */
export function degrees(joints: number[]): number[] {
  return joints.map((value) => Math.round((value * 180) / Math.PI));
}
