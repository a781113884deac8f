// The supervisor pages' script (templates/cases/): keeps the case page's marking, open
// tasks, incidents and timeline up to date, resolves incidents and hands tasks over through
// the REST API.
//
// The live socket (/ws/live/, hrc/live/) is the doorbell: a delta about the page's case
// (or any incident, on the incidents page) makes the page read the REST API again; the
// deltas themselves carry no marking. While the socket is not live the page polls every
// POLL_MS instead, and even while it is, every SAFETY_POLL_MS. A case page asks for events
// and incidents only when the case's last event number has moved.

import type { LiveEvent } from "../live/events";
import { type ConnectionStatus, LiveSocket } from "../live/socket";
import { LiveStore } from "../live/store";
import { pageConfig } from "../shared/dom";
import { getJson, postJson, problemOf } from "../shared/http";
import type { Resolution } from "../shared/choices";
import type { CaseJson, EventJson, IncidentJson, PageJson } from "./api";
import {
  concernsCase,
  concernsIncidents,
  openIncidents,
  pollInterval,
  prettyJson,
  resolveBody,
  taskStates,
  timelineRow,
  touchesInterruptions,
  unseenEvents,
  workRow,
} from "./model";
import {
  applyIncident,
  applyIncidents,
  applyMarking,
  applyStatus,
  prependTimeline,
  renderWorkRows,
  trimTimeline,
} from "./render";

const EVENTS_PER_REQUEST = 200;
// An open page of a long case keeps this many of its newest events; older ones are a link away.
const MAX_TIMELINE_ROWS = 200;

interface CasePageConfig {
  page: "case";
  organisations: number[];
  socket: string;
  case: number;
  lastSeq: number;
  live: boolean;
  labels: Record<string, string>;
  api: { case: string; events: string; incidents: string; resolve: string; workItems: string };
}

interface IncidentsPageConfig {
  page: "incidents";
  organisations: number[];
  socket: string;
  live: boolean;
  api: { incidents: string; resolve: string; case: string };
}

type PageConfig = CasePageConfig | IncidentsPageConfig;

const STATUS_TEXT: Record<ConnectionStatus, string> = {
  connecting: "connecting…",
  live: "live",
  reconnecting: "reconnecting",
  refused: "refused",
};

/**
 * Reads the page's state again when asked (a delta rang, an incident was resolved) and on a
 * timer: POLL_MS while no live socket is up, SAFETY_POLL_MS while one is. Never two reads at
 * once; a request during a read gets one more read after it, so no change is missed.
 */
class Refresher {
  private running: Promise<void> | null = null;
  private again = false;
  private timer = 0;
  private sockets = new Map<number, ConnectionStatus>();

  constructor(private readonly refresh: () => Promise<void>) {
    this.schedule();
  }

  request(): Promise<void> {
    if (this.running) {
      this.again = true;
      return this.running;
    }
    this.running = this.refresh()
      .then(() => this.show(""))
      .catch((error: unknown) => this.show(problemOf(error)))
      .finally(() => {
        this.running = null;
        if (this.again) {
          this.again = false;
          void this.request();
        }
      });
    return this.running;
  }

  /** Follows the organisations' live sockets: a delta that concerns the page rings. */
  listen(config: { organisations: number[]; socket: string }, concerns: (event: LiveEvent) => boolean): void {
    const scheme = window.location.protocol === "https:" ? "wss:" : "ws:";
    for (const organisation of config.organisations) {
      const store = new LiveStore();
      store.subscribe((event) => {
        if (concerns(event)) void this.request();
      });
      this.sockets.set(organisation, "connecting");
      new LiveSocket({
        url: `${scheme}//${window.location.host}${config.socket}?organisation=${organisation}`,
        store,
        onStatus: (status) => {
          this.sockets.set(organisation, status);
          this.show("");
          this.schedule();
        },
      }).start();
    }
  }

  private schedule(): void {
    window.clearTimeout(this.timer);
    this.timer = window.setTimeout(() => {
      void this.request().then(() => this.schedule());
    }, pollInterval([...this.sockets.values()]));
  }

  private show(problem: string): void {
    const status = document.getElementById("live-status");
    if (!status) return;
    const states = [...this.sockets.values()];
    const live = states.length > 0 && states.every((state) => state === "live");
    status.dataset.live = live ? "socket" : "polling";
    const sockets = states.map((state) => STATUS_TEXT[state]).join(", ") || "none";
    const how = live ? "Live" : `Polling every ${pollInterval(states) / 1000} s (live socket: ${sockets})`;
    status.textContent = problem ? `Updates paused: ${problem}` : how;
  }
}

// Resolving incidents -----------------------------------------------------------------------

async function resolve(
  card: HTMLElement,
  resolution: Resolution,
  resolveUrl: string,
): Promise<IncidentJson | null> {
  const errors = card.querySelector(".errors");
  const body = resolveBody(resolution, {
    again: card.querySelector<HTMLInputElement>('input[name="again"]')?.checked ?? false,
    outputs: card.querySelector<HTMLTextAreaElement>('textarea[name="outputs"]')?.value ?? "{}",
  });
  if (errors) errors.textContent = "";
  if (!body.ok) {
    if (errors) errors.textContent = body.message;
    return null;
  }
  const buttons = [...card.querySelectorAll<HTMLButtonElement>("button[data-resolution]")];
  buttons.forEach((button) => (button.disabled = true));
  try {
    const url = resolveUrl.replace(/\/0\/resolve\/$/, `/${card.dataset.incident}/resolve/`);
    const incident = await postJson<IncidentJson>(url, body.value);
    applyIncident(card, incident);
    return incident;
  } catch (error) {
    if (errors) errors.textContent = problemOf(error);
    return null;
  } finally {
    buttons.forEach((button) => (button.disabled = false));
  }
}

function onResolve(resolveUrl: string, after: () => Promise<void>): void {
  document.addEventListener("click", (event) => {
    const button = (event.target as Element | null)?.closest<HTMLButtonElement>("button[data-resolution]");
    const card = button?.closest<HTMLElement>(".incident");
    if (!button || !card) return;
    void resolve(card, button.dataset.resolution as Resolution, resolveUrl).then((done) => {
      if (done) void after();
    });
  });
}

// Handing over a task whose operator has gone -----------------------------------------------

interface Performer {
  id: number;
  username: string;
}

/** A task's "Hand over…" opens the dialog with whom it may go to (the API's performers, but the
 * one who holds it; a claimed task may also go back to its candidates). */
function onReassign(workItemsUrl: string, after: () => Promise<void>): void {
  const dialog = document.querySelector<HTMLDialogElement>("dialog#reassign");
  const form = dialog?.querySelector("form");
  const select = dialog?.querySelector<HTMLSelectElement>('select[name="user"]');
  const errors = dialog?.querySelector<HTMLElement>(".errors");
  const handOver = dialog?.querySelector<HTMLButtonElement>('button[value="hand-over"]');
  if (!dialog || !form || !select || !errors || !handOver) return;
  let item = 0;

  document.addEventListener("click", (event) => {
    const button = (event.target as Element | null)?.closest<HTMLButtonElement>("button[data-reassign]");
    if (!button) return;
    item = Number(button.dataset.reassign);
    dialog.querySelector(".what")!.textContent = button.dataset.label ?? "";
    errors.textContent = "";
    button.disabled = true;
    getJson<Performer[]>(`${workItemsUrl}${item}/performers/`)
      .then((performers) => {
        const options = performers
          .filter((performer) => performer.username !== button.dataset.who)
          .map((performer) => new Option(performer.username, String(performer.id)));
        if (button.dataset.state === "claimed") options.unshift(new Option("Back to its candidates", ""));
        select.replaceChildren(...options);
        if (!options.length) errors.textContent = "Nobody else may do this task.";
      })
      .catch((error: unknown) => {
        select.replaceChildren();
        errors.textContent = problemOf(error);
      })
      .finally(() => {
        button.disabled = false;
        handOver.disabled = select.options.length === 0;
        dialog.showModal();
      });
  });

  form.addEventListener("submit", (event) => {
    if (event.submitter !== handOver) return; // Cancel closes the dialog
    event.preventDefault();
    handOver.disabled = true;
    const user = select.value ? Number(select.value) : null;
    postJson(`${workItemsUrl}${item}/reassign/`, { user })
      .then(() => {
        dialog.close();
        void after();
      })
      .catch((error: unknown) => {
        errors.textContent = problemOf(error);
      })
      .finally(() => (handOver.disabled = false));
  });
}

// The case page -----------------------------------------------------------------------------

async function allEventsAfter(url: string, after: number): Promise<EventJson[]> {
  const events: EventJson[] = [];
  let next: string | null = `${url}?after=${after}&limit=${EVENTS_PER_REQUEST}`;
  while (next) {
    const page: PageJson<EventJson> = await getJson<PageJson<EventJson>>(next);
    events.push(...page.results);
    next = page.next;
  }
  return events;
}

/** Points the timeline's "Older events" link at the events before `seq`. */
function showOlder(seq: number): void {
  const pager = document.querySelector('nav[aria-label="Timeline pages"]');
  if (!pager) return;
  let link = pager.querySelector<HTMLAnchorElement>('a[rel="next"]');
  if (!link) {
    link = document.createElement("a");
    link.rel = "next";
    link.textContent = "Older events";
    pager.append(link);
  }
  link.href = `?before=${seq}`;
}

/** Swaps the interruptions table for the server's current one (no API lists interruptions). */
async function refreshInterruptions(): Promise<void> {
  const response = await fetch(window.location.href, { credentials: "same-origin" });
  if (!response.ok) return;
  const fresh = new DOMParser().parseFromString(await response.text(), "text/html");
  const section = fresh.getElementById("interruptions");
  if (section) document.getElementById("interruptions")?.replaceWith(section);
}

function startCasePage(config: CasePageConfig): void {
  const net = document.querySelector("svg.net");
  const tasks = [...document.querySelectorAll<SVGGElement>("svg.net [data-task]")].map((t) => t.dataset.task ?? "");
  const incidents = document.getElementById("incidents");
  let lastSeq = config.lastSeq;

  const refresh = async (): Promise<void> => {
    const current = await getJson<CaseJson>(config.api.case);
    const badge = document.getElementById("case-status");
    if (badge) applyStatus(badge, current.status);
    if (net) {
      const states = taskStates(tasks, current.marking, current.work_items, openIncidents(current));
      applyMarking(net, current.marking, states);
    }
    const workBody = document.querySelector<HTMLTableSectionElement>("#work-items tbody");
    if (workBody) renderWorkRows(workBody, current.work_items.map(workRow));
    const data = document.getElementById("case-data");
    if (data) data.textContent = prettyJson(current.data);
    if (current.last_seq <= lastSeq) return;
    const events = unseenEvents(lastSeq, await allEventsAfter(config.api.events, lastSeq));
    if (config.live) {
      const timeline = document.querySelector<HTMLTableSectionElement>("#timeline tbody");
      if (timeline) {
        prependTimeline(timeline, events.map((event) => timelineRow(event, config.labels)));
        const oldest = trimTimeline(timeline, MAX_TIMELINE_ROWS);
        if (oldest !== null) showOlder(oldest);
      }
    }
    if (incidents) {
      const page = await getJson<PageJson<IncidentJson>>(config.api.incidents);
      applyIncidents(incidents, page.results);
      document.querySelector<HTMLElement>("#incidents + .empty")?.toggleAttribute("hidden", page.results.length > 0);
    }
    if (touchesInterruptions(events)) await refreshInterruptions();
    lastSeq = Math.max(lastSeq, ...events.map((event) => event.seq));
  };

  const refresher = new Refresher(refresh);
  refresher.listen(config, (event) => concernsCase(event, config.case));
  onResolve(config.api.resolve, () => refresher.request());
  onReassign(config.api.workItems, () => refresher.request());
}

// The incidents page ------------------------------------------------------------------------

function startIncidentsPage(config: IncidentsPageConfig): void {
  const list = document.getElementById("incidents");
  if (!list) return;
  const options = { caseUrl: config.api.case };

  const refresh = async (): Promise<void> => {
    const open = await getJson<PageJson<IncidentJson>>(`${config.api.incidents}?limit=100`);
    if (config.live) applyIncidents(list, open.results, options);
    const openIds = new Set(open.results.map((incident) => incident.id));
    // Cards whose incident someone resolved elsewhere: ask how, once.
    for (const card of list.querySelectorAll<HTMLElement>(".incident:not(.resolved)")) {
      const id = Number(card.dataset.incident);
      if (openIds.has(id)) continue;
      applyIncident(card, await getJson<IncidentJson>(`${config.api.incidents}${id}/`));
    }
    document.querySelector<HTMLElement>("p.empty")?.toggleAttribute("hidden", list.children.length > 0);
  };

  const refresher = new Refresher(refresh);
  refresher.listen(config, concernsIncidents);
  onResolve(config.api.resolve, () => refresher.request());
}

function start(): void {
  const config = pageConfig<PageConfig>("supervisor-page");
  if (!config) return;
  if (config.page === "case") startCasePage(config);
  else startIncidentsPage(config);
}

start();
