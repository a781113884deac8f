// The supervisor pages' script (templates/cases/): keeps the case page's marking, open
// tasks, incidents and timeline up to date, and resolves incidents through the REST API.
//
// Updates come by polling the API every POLL_MS; a case page asks for the events and
// incidents only when the case's last event number has moved, so an idle case costs one
// small request per poll.

import {
  Refusal,
  getJson,
  postJson,
  type CaseJson,
  type EventJson,
  type IncidentJson,
  type PageJson,
} from "./api";
import {
  openIncidents,
  prettyJson,
  resolveBody,
  taskStates,
  timelineRow,
  touchesInterruptions,
  unseenEvents,
  workRow,
  type Resolution,
} from "./model";
import {
  applyIncident,
  applyIncidents,
  applyMarking,
  applyStatus,
  prependTimeline,
  renderWorkRows,
} from "./render";

export const POLL_MS = 2000;
const EVENTS_PER_REQUEST = 200;

interface CasePageConfig {
  page: "case";
  case: number;
  lastSeq: number;
  live: boolean;
  labels: Record<string, string>;
  api: { case: string; events: string; incidents: string; resolve: string };
}

interface IncidentsPageConfig {
  page: "incidents";
  live: boolean;
  api: { incidents: string; resolve: string; case: string };
}

type PageConfig = CasePageConfig | IncidentsPageConfig;

function csrfToken(): string {
  return document.querySelector<HTMLMetaElement>('meta[name="csrf-token"]')?.content ?? "";
}

function liveStatus(text: string): void {
  const status = document.getElementById("live-status");
  if (status) status.textContent = text;
}

/** Runs `refresh` every POLL_MS, never two at once; a failure is shown and retried. */
function poll(refresh: () => Promise<void>): { now: () => Promise<void> } {
  let running: Promise<void> | null = null;
  const once = async (): Promise<void> => {
    if (running) return running;
    running = refresh()
      .then(() => liveStatus(""))
      .catch((error: unknown) => {
        const message = error instanceof Refusal ? error.message : String(error);
        liveStatus(`Live updates paused: ${message}`);
      })
      .finally(() => {
        running = null;
      });
    return running;
  };
  const loop = (): void => {
    void once().then(() => window.setTimeout(loop, POLL_MS));
  };
  window.setTimeout(loop, POLL_MS);
  return { now: once };
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
    const incident = await postJson<IncidentJson>(url, body.value, csrfToken());
    applyIncident(card, incident);
    return incident;
  } catch (error) {
    if (errors) errors.textContent = error instanceof Refusal ? error.message : String(error);
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
    if (net) applyMarking(net, current.marking, taskStates(tasks, current.marking, current.work_items, openIncidents(current)));
    const workBody = document.querySelector<HTMLTableSectionElement>("#work-items tbody");
    if (workBody) renderWorkRows(workBody, current.work_items.map(workRow));
    const data = document.getElementById("case-data");
    if (data) data.textContent = prettyJson(current.data);
    if (current.last_seq <= lastSeq) return;
    const events = unseenEvents(lastSeq, await allEventsAfter(config.api.events, lastSeq));
    if (config.live) {
      const timeline = document.querySelector<HTMLTableSectionElement>("#timeline tbody");
      if (timeline) prependTimeline(timeline, events.map((event) => timelineRow(event, config.labels)));
    }
    if (incidents) {
      const page = await getJson<PageJson<IncidentJson>>(config.api.incidents);
      applyIncidents(incidents, page.results);
      document.querySelector<HTMLElement>("#incidents + .empty")?.toggleAttribute("hidden", page.results.length > 0);
    }
    if (touchesInterruptions(events)) await refreshInterruptions();
    lastSeq = Math.max(lastSeq, ...events.map((event) => event.seq));
  };

  const poller = poll(refresh);
  onResolve(config.api.resolve, poller.now);
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

  const poller = poll(refresh);
  onResolve(config.api.resolve, poller.now);
}

function start(): void {
  const source = document.getElementById("supervisor-page");
  if (!source?.textContent) return;
  const config = JSON.parse(source.textContent) as PageConfig;
  if (config.page === "case") startCasePage(config);
  else startIncidentsPage(config);
}

start();
