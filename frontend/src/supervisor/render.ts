// The page's DOM, kept the shape the server renders it in (templates/cases/): the net's
// tokens and task states, incident cards, the open tasks, timeline rows.

import { CASE_STATUSES, INCIDENT_KINDS } from "../shared/choices";
import { element } from "../shared/dom";
import type { IncidentJson, Marking } from "./api";
import {
  constraintTokens,
  formatTime,
  outcomeText,
  prettyJson,
  tokenText,
  type TaskState,
  type TimelineRow,
  type WorkRow,
} from "./model";

/** Puts the marking and the task states on the drawn net. */
export function applyMarking(net: Element, marking: Marking, states: Map<string, TaskState>): void {
  for (const place of net.querySelectorAll<SVGGElement>("[data-place]")) {
    const tokens = marking[place.dataset.place ?? ""] ?? 0;
    place.dataset.tokens = String(tokens);
    place.classList.toggle("marked", tokens > 0);
    const text = place.querySelector(".tokens");
    if (text) text.textContent = tokenText(tokens);
  }
  for (const task of net.querySelectorAll<SVGGElement>("[data-task]")) {
    const state = states.get(task.dataset.task ?? "") ?? "";
    task.dataset.state = state;
    for (const name of ["incident", "running", "offered"]) task.classList.toggle(name, name === state);
  }
  for (const line of net.querySelectorAll<SVGGElement>("[data-places]")) {
    const places = (line.dataset.places ?? "").split(" ").filter(Boolean);
    const tokens = constraintTokens(places, marking);
    const text = line.querySelector<SVGTSpanElement>(".tokens");
    if (text) {
      text.dataset.tokens = String(tokens);
      text.textContent = tokens ? ` ●${tokens}` : "";
    }
  }
}

export function applyStatus(badge: HTMLElement, status: string): void {
  badge.className = `status ${status}`;
  badge.textContent = CASE_STATUSES[status] ?? status;
}

function time(iso: string): HTMLTimeElement {
  return element("time", { datetime: iso }, formatTime(iso));
}

export interface IncidentOptions {
  /** The case page's URL with 0 for the id (/cases/0/); given on the incidents page. */
  caseUrl?: string;
}

/** An incident card with its resolve controls, as templates/cases/_incident.html draws one. */
export function renderIncident(incident: IncidentJson, options: IncidentOptions = {}): HTMLElement {
  const head = element("div", {}, element("strong", { class: "kind" }, INCIDENT_KINDS[incident.kind] ?? incident.kind));
  if (options.caseUrl) {
    const url = options.caseUrl.replace(/\/0\/$/, `/${incident.case}/`);
    head.append(" in ", element("a", { href: url }, `case ${incident.case}`));
  }
  if (incident.task) head.append(" · task ", element("code", { class: "task" }, incident.task));
  head.append(" · ", element("span", { class: "muted" }, "opened ", time(incident.opened_at)));
  const card = element(
    "article",
    {
      class: "incident",
      "data-incident": String(incident.id),
      "data-case": String(incident.case),
      "aria-label": `Incident ${incident.id}`,
    },
    head,
    element("p", { class: "message" }, incident.message),
  );
  if (incident.cobot_state) {
    card.append(
      element(
        "details",
        {},
        element("summary", {}, "Cobot state"),
        element("pre", { class: "json" }, prettyJson(incident.cobot_state)),
      ),
    );
  }
  const outputs = element("textarea", { name: "outputs", spellcheck: "false" });
  outputs.value = "{}";
  card.append(
    element(
      "div",
      { class: "resolve" },
      element("button", { type: "button", "data-resolution": "retry" }, "Retry"),
      element("label", {}, element("input", { type: "checkbox", name: "again" }), " as a new attempt"),
      element("label", {}, "Outputs (JSON)", element("br"), outputs),
      element("button", { type: "button", "data-resolution": "skip" }, "Skip with outputs"),
      element("button", { type: "button", "data-resolution": "cancel" }, "Cancel the case"),
    ),
    element("p", { class: "outcome", role: "status" }),
    element("p", { class: "errors", role: "alert" }),
  );
  applyIncident(card, incident);
  return card;
}

/** Shows on a card whether (and how) its incident was resolved. */
export function applyIncident(card: HTMLElement, incident: IncidentJson): void {
  card.classList.toggle("resolved", Boolean(incident.resolved_at));
  const outcome = card.querySelector(".outcome");
  if (outcome && incident.resolved_at) outcome.textContent = outcomeText(incident);
}

/** Adds cards for incidents not on the page yet (newest on top) and updates the others. */
export function applyIncidents(
  list: HTMLElement,
  incidents: readonly IncidentJson[],
  options: IncidentOptions = {},
): void {
  const newestFirst = [...incidents].sort((a, b) => b.id - a.id);
  for (const incident of [...newestFirst].reverse()) {
    const card = list.querySelector<HTMLElement>(`[data-incident="${incident.id}"]`);
    if (card) applyIncident(card, incident);
    else list.prepend(renderIncident(incident, options));
  }
}

export function renderWorkRows(body: HTMLTableSectionElement, rows: readonly WorkRow[]): void {
  const lines = rows.map((row) =>
    element(
      "tr",
      { "data-task": row.task },
      element("td", {}, `${row.label} `, element("code", { class: "muted" }, row.task)),
      element("td", {}, row.state),
      element("td", {}, row.who),
      element("td", {}, row.job),
      element("td", {}, ...(row.reassignable ? [reassignButton(row)] : [])),
    ),
  );
  if (!lines.length) {
    const none = element("td", { colspan: "5", class: "muted" }, "No open tasks.");
    lines.push(element("tr", { class: "none" }, none));
  }
  body.replaceChildren(...lines);
}

function reassignButton(row: WorkRow): HTMLButtonElement {
  const attributes = {
    type: "button",
    "data-reassign": String(row.id),
    "data-state": row.state,
    "data-label": row.label,
    "data-who": row.who,
  };
  return element("button", attributes, "Hand over…");
}

export function renderTimelineRow(row: TimelineRow): HTMLTableRowElement {
  const task = row.task ? [`${row.taskLabel} `, element("code", { class: "muted" }, row.task)] : [];
  return element(
    "tr",
    { "data-seq": String(row.seq), "data-type": row.type, class: "fresh" },
    element("td", {}, String(row.seq)),
    element("td", {}, element("time", { datetime: row.at }, row.when)),
    element("td", {}, row.who),
    element("td", {}, row.what),
    element("td", {}, ...task),
    element("td", { class: "change" }, row.change),
    element("td", { class: "detail" }, row.detail),
  );
}

/** Puts new rows on top of the timeline (newest first), skipping any already there. */
export function prependTimeline(body: HTMLTableSectionElement, rows: readonly TimelineRow[]): void {
  for (const row of rows) {
    if (body.querySelector(`tr[data-seq="${row.seq}"]`)) continue;
    body.prepend(renderTimelineRow(row));
  }
}

/**
 * Keeps the newest `max` rows of a timeline that has grown on an open page; returns the seq
 * of the oldest row kept (where the "older events" link starts), or null when none was cut.
 */
export function trimTimeline(body: HTMLTableSectionElement, max: number): number | null {
  const rows = [...body.querySelectorAll<HTMLTableRowElement>("tr[data-seq]")];
  if (rows.length <= max) return null;
  rows.slice(max).forEach((row) => row.remove());
  return Number(rows[max - 1].dataset.seq);
}
