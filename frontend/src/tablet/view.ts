// What the tablet shows, derived from the live state: pure functions, tested without a page.

import type { CobotData, TimerData, WorkItemData } from "../live/events";
import { type LiveState, timersByDue } from "../live/store";

/** Operator tasks that are the user's: claimed or started by them, wherever their case runs, and
 * those offered to them by name at this tablet's cell (see `atThisCell`). */
export function myTasks(state: LiveState): WorkItemData[] {
  return sorted(
    [...state.workItems.values()].filter(
      (item) => isMine(state, item) && (item.claimed_by === state.user.id || atThisCell(state, item)),
    ),
  );
}

/** Open operator tasks of the user's teams that nobody has taken, at this tablet's cell: theirs to claim. */
export function teamTasks(state: LiveState): WorkItemData[] {
  return sorted([...state.workItems.values()].filter((item) => isTeams(state, item) && atThisCell(state, item)));
}

/** The tasks the user could take that a cell's tablet leaves out: they wait at other cells. */
export function elsewhere(state: LiveState): WorkItemData[] {
  return sorted(
    [...state.workItems.values()].filter(
      (item) => item.claimed_by === null && (isMine(state, item) || isTeams(state, item)) && !atThisCell(state, item),
    ),
  );
}

/** The cells the items' cases work at, by name: where an operator goes to do them. Empty when
 * none is known (a cobot registered after the snapshot, one that stands in no cell). */
export function cellsOf(state: LiveState, items: WorkItemData[]): string[] {
  const cells = new Set<string>();
  for (const item of items) {
    for (const id of state.cases.get(item.case)?.cobots ?? []) {
      const cell = state.floor.get(id)?.cell;
      if (cell) cells.add(cell);
    }
  }
  return [...cells].sort();
}

/** "the paint cell", "the paint and weld cells"; "another cell" when none is known. */
export function cellWords(cells: string[], many = false): string {
  if (!cells.length) return many ? "other cells" : "another cell";
  if (cells.length === 1) return `the ${cells[0]} cell`;
  return `the ${cells.slice(0, -1).join(", ")} and ${cells[cells.length - 1]} cells`;
}

/** Whether the item's case works at this tablet's cell. A tablet of the whole floor (no cell)
 * shows every case. A cell's tablet knows that cell's cobots only (the server sends no others):
 * it shows the cases that use one of them, and those that use no cobot, which belong to no cell.
 * A task the user already holds is theirs to finish wherever it is, so callers keep it anyway. */
export function atThisCell(state: LiveState, item: WorkItemData): boolean {
  return caseAtThisCell(state, item.case);
}

function caseAtThisCell(state: LiveState, caseId: number): boolean {
  if (!state.cell) return true;
  const cobots = state.cases.get(caseId)?.cobots ?? [];
  return cobots.length === 0 || cobots.some((id) => state.cobots.has(id));
}

function isMine(state: LiveState, item: WorkItemData): boolean {
  const me = state.user.id;
  return (
    item.kind === "operator" &&
    (item.claimed_by === me || (item.claimed_by === null && item.state === "offered" && item.candidates.includes(me)))
  );
}

function isTeams(state: LiveState, item: WorkItemData): boolean {
  return (
    item.kind === "operator" &&
    item.state === "offered" &&
    item.claimed_by === null &&
    item.team !== null &&
    state.user.teams.includes(item.team) &&
    !item.candidates.includes(state.user.id)
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

/** One line per cobot of the task's case: what it is doing for this case. Its work for another
 * case is not this task's, so the card says only that the cobot is busy with another case. */
export function cobotWork(state: LiveState, item: WorkItemData): string[] {
  return cobotsOf(state, item).map((cobot) => `${cobot.name}: ${workFor(cobot, item.case)}`);
}

function workFor(cobot: CobotData, caseId: number): string {
  const current = cobot.queue.current;
  if (!current || current.case === caseId) return activity(cobot);
  // A STOP, a fault or a lost connection is the cell's news, whichever case the cobot serves.
  return trouble(cobot) ?? "busy with another case";
}

/** One line: what the cobot is doing right now, or waiting for. */
export function activity(cobot: CobotData): string {
  const problem = trouble(cobot);
  if (problem) return problem;
  const current = cobot.queue.current;
  if (current) {
    const step = current.step !== null ? ` (step ${current.step})` : "";
    const paused = cobot.state?.program_state === "Paused" ? ", paused" : "";
    return `${current.label || current.task}${step}, case ${current.case}${paused}`;
  }
  if (cobot.queue.waiting_for) return `waiting: ${cobot.queue.waiting_for}`;
  return cobot.queue.queue_length ? `${cobot.queue.queue_length} queued` : "idle";
}

/** What keeps the cobot from working, whatever it works on; null when nothing does. */
function trouble(cobot: CobotData): string | null {
  const state = cobot.state;
  if (cobot.stopped) return "held by STOP";
  if (state && !state.reachable) return `unreachable${state.error ? `: ${state.error}` : ""}`;
  if (state && !["SAFETY_MODE_NORMAL", "SAFETY_MODE_REDUCED"].includes(state.safety_mode)) {
    return `${humanSafety(state.safety_mode)}: clear it at the robot`;
  }
  return null;
}

export function humanSafety(mode: string): string {
  return mode.replace(/^SAFETY_MODE_/, "").replace(/_/g, " ").toLowerCase();
}

/** What the task's button does next: claim, start, complete, or (a cancelled task whose
 * operator may still be in the shared area) say they have left; null when nothing. */
export function nextAction(
  state: LiveState,
  item: WorkItemData,
): "claim" | "start" | "complete" | "left-area" | null {
  const me = state.user.id;
  if (item.state === "cancelled") return item.in_area && item.claimed_by === me ? "left-area" : null;
  if (item.state === "running") return item.claimed_by === me ? "complete" : null;
  if (item.state === "claimed") return item.claimed_by === me ? "start" : null;
  if (item.state === "offered") return item.candidates.includes(me) ? "start" : "claim";
  return null;
}

/** Whether the user may give the task back to its team or candidates: they claimed it and have
 * not started it. A started task stays with whoever started it (an engineer can reassign it). */
export function mayGiveBack(state: LiveState, item: WorkItemData): boolean {
  return item.state === "claimed" && item.claimed_by === state.user.id;
}

/** A text a cobot's display showed, at the time it appeared there. */
export interface DisplayMessage {
  cobot: number;
  name: string;
  text: string;
  at: number; // seconds since the epoch
}

/** `messages` with the texts the cobots' displays show now, newest first, at most `max`. A text
 * is one message however often it is sent again (each state, each snapshot after a reconnect or
 * a resync): it is known by its cobot and the time it appeared, and keeps that time. */
export function withDisplayMessages(messages: DisplayMessage[], cobots: Iterable<CobotData>, max: number): DisplayMessage[] {
  const known = new Set(messages.map((message) => `${message.cobot}@${message.at}`));
  const added: DisplayMessage[] = [];
  for (const cobot of cobots) {
    const state = cobot.state;
    if (!state?.display || known.has(`${cobot.id}@${state.display_at}`)) continue;
    added.push({ cobot: cobot.id, name: cobot.name, text: state.display, at: state.display_at });
  }
  if (!added.length) return messages;
  return [...added, ...messages].sort((a, b) => b.at - a.at).slice(0, max);
}

/** Joint angles in degrees, for the panel. */
export function degrees(joints: number[]): number[] {
  return joints.map((value) => Math.round((value * 180) / Math.PI));
}

/** The armed timers of the cases this tablet shows, soonest due first (a case may wait for a
 * timer with no task open, so they are listed apart from the cards too). */
export function waitingTimers(state: LiveState): TimerData[] {
  return timersByDue(state.timers.values()).filter((timer) => caseAtThisCell(state, timer.case));
}

/** The armed timers the item's case waits for, soonest due first. */
export function timersOf(state: LiveState, caseId: number): TimerData[] {
  return timersByDue(state.timers.values()).filter((timer) => timer.case === caseId);
}

/** "waiting until HH:MM:SS (label)", in the tablet's local time, as the case page says it. */
export function waitingLine(timer: TimerData): string {
  const due = new Date(timer.due_at);
  const clock = [due.getHours(), due.getMinutes(), due.getSeconds()].map((n) => String(n).padStart(2, "0"));
  return `waiting until ${clock.join(":")} (${timer.label || timer.transition})`;
}
