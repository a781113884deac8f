// Pure functions of the supervisor pages: what the marking, the open work and the event
// log mean on the page. The server renders the first view with the same rules
// (hrc/cases/views.py); these keep it up to date.

import type { LiveEvent } from "../live/events";
import { EVENT_TYPES, OPEN_WORK_ITEM_STATES, type Resolution } from "../shared/choices";
import type { ConnectionStatus } from "../live/socket";
import type { CaseJson, EventJson, IncidentJson, JobJson, Marking, WorkItemJson } from "./api";

/** How often the page reads the API without a live socket, and with one (to catch a missed ring). */
export const POLL_MS = 2000;
export const SAFETY_POLL_MS = 30_000;

/** The polling interval for these live sockets' states: slow only while every one is live. */
export function pollInterval(sockets: readonly ConnectionStatus[]): number {
  return sockets.length > 0 && sockets.every((status) => status === "live") ? SAFETY_POLL_MS : POLL_MS;
}

/** Whether a live event may change a case page: a (re)connection's snapshot, or a delta of the case. */
export function concernsCase(event: LiveEvent, caseId: number): boolean {
  if (event.type === "snapshot") return true;
  if (event.type === "case" || event.type === "work-item" || event.type === "incident") return event.case === caseId;
  return false;
}

/** Whether a live event may change the incidents page: a snapshot or any incident delta. */
export function concernsIncidents(event: LiveEvent): boolean {
  return event.type === "snapshot" || event.type === "incident";
}

export type TaskState = "incident" | "running" | "offered" | "";

/** A place's tokens as drawn: nothing, one dot, or the number. */
export function tokenText(tokens: number): string {
  if (tokens <= 0) return "";
  return tokens === 1 ? "●" : String(tokens);
}

/** The tokens in a constraint's places (a time constraint's completions not yet used, …). */
export function constraintTokens(places: readonly string[], marking: Marking): number {
  return places.reduce((sum, place) => sum + (marking[place] ?? 0), 0);
}

/**
 * How each task is drawn: an open incident about it first, then running (its `running:`
 * place holds a token), then offered (an open work item nobody has started).
 */
export function taskStates(
  tasks: readonly string[],
  marking: Marking,
  items: readonly WorkItemJson[],
  openIncidents: readonly IncidentJson[],
): Map<string, TaskState> {
  const troubled = new Set(openIncidents.map((incident) => incident.task).filter(Boolean));
  const offered = new Set(
    items.filter((item) => item.state === "offered" || item.state === "claimed").map((i) => i.task),
  );
  const states = new Map<string, TaskState>();
  for (const task of tasks) {
    if (troubled.has(task)) states.set(task, "incident");
    else if ((marking[`running:${task}`] ?? 0) > 0) states.set(task, "running");
    else if (offered.has(task)) states.set(task, "offered");
    else states.set(task, "");
  }
  return states;
}

/** What an event did to the marking, place by place: ["p1 −1", "running:to1 +1"]. */
export function markingChange(before: Marking, after: Marking): string[] {
  const places = [...new Set([...Object.keys(before), ...Object.keys(after)])].sort();
  const changes: string[] = [];
  for (const place of places) {
    const delta = (after[place] ?? 0) - (before[place] ?? 0);
    if (delta) changes.push(`${place} ${delta > 0 ? "+" : "−"}${Math.abs(delta)}`);
  }
  return changes;
}

/** An ISO time as the pages print it, in UTC (the server's time zone): 2025-01-31 13:05:09. */
export function formatTime(iso: string): string {
  const at = new Date(iso);
  if (Number.isNaN(at.getTime())) return iso;
  return at.toISOString().slice(0, 19).replace("T", " ");
}

export interface TimelineRow {
  seq: number;
  at: string;
  when: string;
  who: string;
  what: string;
  type: string;
  task: string;
  taskLabel: string;
  change: string;
  detail: string;
}

function short(value: unknown): string {
  const text = typeof value === "string" ? value : JSON.stringify(sortKeys(value));
  return text.length <= 80 ? text : `${text.slice(0, 79)}…`;
}

function sortKeys(value: unknown): unknown {
  if (Array.isArray(value)) return value.map(sortKeys);
  if (value && typeof value === "object") {
    const entries = Object.entries(value as Record<string, unknown>).sort(([a], [b]) =>
      a < b ? -1 : a > b ? 1 : 0,
    );
    return Object.fromEntries(entries.map(([key, item]) => [key, sortKeys(item)]));
  }
  return value;
}

/** An event as a timeline row: who (the user, else the pattern actor, else hrc), what, when. */
export function timelineRow(event: EventJson, labels: Record<string, string>): TimelineRow {
  return {
    seq: event.seq,
    at: event.at,
    when: formatTime(event.at),
    who: event.user || event.actor || "hrc",
    what: EVENT_TYPES[event.type] ?? event.type,
    type: event.type,
    task: event.task,
    taskLabel: labels[event.task] ?? event.task,
    change: markingChange(event.marking_before, event.marking_after).join(", "),
    detail: Object.entries(event.detail)
      .map(([key, value]) => `${key}: ${short(value)}`)
      .join(", "),
  };
}

/** The events not shown yet (seq after `lastSeq`), oldest first, each once. */
export function unseenEvents(lastSeq: number, events: readonly EventJson[]): EventJson[] {
  const bySeq = new Map<number, EventJson>();
  for (const event of events) if (event.seq > lastSeq) bySeq.set(event.seq, event);
  return [...bySeq.values()].sort((a, b) => a.seq - b.seq);
}

/** Whether these events change what the interruptions table shows. */
export function touchesInterruptions(events: readonly EventJson[]): boolean {
  return events.some((e) => ["task-interrupted", "task-resumed", "task-kept-out"].includes(e.type));
}

export interface WorkRow {
  task: string;
  label: string;
  state: string;
  who: string;
  job: string;
  id: number;
  reassignable: boolean; // an operator task still open: a supervisor may hand it over
}

function jobText(job: JobJson | null): string {
  if (!job) return "";
  if (job.state === "queued") {
    const text = job.queue_position === null ? "queued" : `queued, position ${job.queue_position}`;
    return job.waiting_for ? `${text}; waiting for ${job.waiting_for}` : text;
  }
  if (job.state === "running") return `running, attempt ${job.attempt}`;
  return job.last_error ? `${job.state}: ${job.last_error}` : job.state;
}

/** An open work item as the page lists it (views.work_row says it the same way). */
export function workRow(item: WorkItemJson): WorkRow {
  return {
    task: item.task,
    label: item.label || item.task,
    state: item.state,
    who: item.claimed_by || item.job?.cobot_name || item.job?.device_name || "–",
    job: jobText(item.job),
    id: item.id,
    reassignable: item.kind === "operator" && OPEN_WORK_ITEM_STATES.has(item.state),
  };
}

export type Checked<T> = { ok: true; value: T } | { ok: false; message: string };

export interface ResolveBody {
  resolution: Resolution;
  again?: boolean;
  outputs?: Record<string, unknown>;
}

/**
 * The body of a resolve request, or why it cannot be sent: skip's outputs must be a JSON
 * object (the task's result); retry's `again` asks for a new attempt of a step.
 */
export function resolveBody(
  resolution: Resolution,
  options: { again: boolean; outputs: string },
): Checked<ResolveBody> {
  if (resolution === "retry") return { ok: true, value: { resolution, again: options.again } };
  if (resolution === "cancel") return { ok: true, value: { resolution } };
  const text = options.outputs.trim() || "{}";
  let outputs: unknown;
  try {
    outputs = JSON.parse(text);
  } catch (error) {
    const reason = error instanceof Error ? error.message : String(error);
    return { ok: false, message: `The outputs are not JSON: ${reason}` };
  }
  if (!outputs || typeof outputs !== "object" || Array.isArray(outputs)) {
    return { ok: false, message: 'The outputs must be a JSON object, such as {"placed": true}.' };
  }
  return { ok: true, value: { resolution, outputs: outputs as Record<string, unknown> } };
}

/** What a resolved incident card says: "Resolved: skip by erik-engineer". */
export function outcomeText(incident: IncidentJson): string {
  if (!incident.resolved_at) return "";
  const by = incident.resolved_by ? ` by ${incident.resolved_by}` : "";
  return `Resolved: ${incident.resolution}${by}`;
}

/** The open incidents of a case as its detail carries them. */
export function openIncidents(caseJson: CaseJson): IncidentJson[] {
  return caseJson.incidents.filter((incident) => !incident.resolved_at);
}

/** JSON as the page shows it: indented, keys sorted (as the server's pretty_json). */
export function prettyJson(value: unknown): string {
  return JSON.stringify(sortKeys(value), null, 2);
}
