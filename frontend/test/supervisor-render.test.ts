import { beforeEach, describe, expect, it } from "vitest";

import type { IncidentJson } from "../src/supervisor/api";
import { taskStates, timelineRow } from "../src/supervisor/model";
import {
  applyIncidents,
  applyMarking,
  applyStatus,
  prependTimeline,
  renderIncident,
  renderWorkRows,
  trimTimeline,
} from "../src/supervisor/render";

// The shape templates/cases/_net.html draws.
const NET = `
<svg class="net" xmlns="http://www.w3.org/2000/svg">
  <g class="constraint time" data-places="time:to1>tc1"><path/><text>time<tspan class="tokens" data-tokens="0"></tspan></text></g>
  <g class="transition task offered" data-task="to1" data-state="offered"><rect/></g>
  <g class="transition task" data-task="tc1" data-state=""><rect/></g>
  <g class="place marked" data-place="p1" data-tokens="1"><circle/><text class="tokens">●</text></g>
  <g class="place" data-place="p2" data-tokens="0"><circle/><text class="tokens"></text></g>
</svg>`;

function incident(extra: Partial<IncidentJson> = {}): IncidentJson {
  return {
    id: 7,
    case: 3,
    work_item: 11,
    task: "tc1",
    kind: "step-failed",
    message: "Protective stop",
    cobot_state: { RobotMode: 7 },
    opened_at: "2025-03-01T10:00:00Z",
    resolved_at: null,
    resolution: "",
    resolved_by: null,
    ...extra,
  };
}

beforeEach(() => {
  document.body.innerHTML = "";
});

describe("the net", () => {
  it("moves the tokens and the task states to a new marking", () => {
    document.body.innerHTML = NET;
    const net = document.querySelector("svg")!;
    const marking = { p2: 2, "running:tc1": 1, "time:to1>tc1": 1 };

    applyMarking(net, marking, taskStates(["to1", "tc1"], marking, [], []));

    const p1 = net.querySelector<SVGGElement>('[data-place="p1"]')!;
    const p2 = net.querySelector<SVGGElement>('[data-place="p2"]')!;
    expect([p1.dataset.tokens, p1.classList.contains("marked"), p1.textContent]).toEqual(["0", false, ""]);
    expect([p2.dataset.tokens, p2.classList.contains("marked"), p2.textContent]).toEqual(["2", true, "2"]);
    const to1 = net.querySelector<SVGGElement>('[data-task="to1"]')!;
    const tc1 = net.querySelector<SVGGElement>('[data-task="tc1"]')!;
    expect([to1.dataset.state, to1.classList.contains("offered")]).toEqual(["", false]);
    expect([tc1.dataset.state, tc1.classList.contains("running")]).toEqual(["running", true]);
    expect(net.querySelector(".constraint .tokens")!.textContent).toBe(" ●1");
  });

  it("shows the case's status", () => {
    const badge = document.createElement("span");
    applyStatus(badge, "completed");
    expect([badge.className, badge.textContent]).toEqual(["status completed", "Completed"]);
  });
});

describe("incident cards", () => {
  it("draws an open incident with its three ways to resolve it", () => {
    const card = renderIncident(incident());
    expect(card.dataset.incident).toBe("7");
    expect(card.classList.contains("resolved")).toBe(false);
    expect(card.querySelector(".kind")!.textContent).toBe("Cobot step failed");
    expect(card.querySelector(".message")!.textContent).toBe("Protective stop");
    expect(card.querySelector("pre")!.textContent).toContain('"RobotMode": 7');
    const buttons = [...card.querySelectorAll<HTMLButtonElement>("button[data-resolution]")];
    expect(buttons.map((b) => [b.dataset.resolution, b.textContent])).toEqual([
      ["retry", "Retry"],
      ["skip", "Skip with outputs"],
      ["cancel", "Cancel the case"],
    ]);
    expect(card.querySelector<HTMLTextAreaElement>("textarea")!.value).toBe("{}");
    expect(card.querySelector("a")).toBeNull();
  });

  it("links the case on the incidents page", () => {
    const card = renderIncident(incident({ case: 42 }), { caseUrl: "/cases/0/" });
    expect(card.querySelector("a")!.getAttribute("href")).toBe("/cases/42/");
  });

  it("adds new incidents on top and marks resolved ones", () => {
    const list = document.createElement("div");
    list.append(renderIncident(incident({ id: 7 })));
    applyIncidents(list, [
      incident({ id: 7, resolved_at: "2025-03-01T10:01:00Z", resolution: "retry", resolved_by: "erik" }),
      incident({ id: 9 }),
      incident({ id: 8 }),
    ]);
    expect([...list.children].map((c) => (c as HTMLElement).dataset.incident)).toEqual(["9", "8", "7"]);
    const old = list.querySelector<HTMLElement>('[data-incident="7"]')!;
    expect(old.classList.contains("resolved")).toBe(true);
    expect(old.querySelector(".outcome")!.textContent).toBe("Resolved: retry by erik");
  });
});

describe("tables", () => {
  it("lists the open tasks, or says there are none", () => {
    document.body.innerHTML = "<table><tbody></tbody></table>";
    const body = document.querySelector("tbody")!;
    const step = { task: "tc1", label: "pick", state: "offered", who: "cobot1", job: "queued, position 1" };
    const held = { task: "to1", label: "place", state: "claimed", who: "olivia", job: "", id: 8 };
    renderWorkRows(body, [
      { ...step, id: 7, reassignable: false },
      { ...held, reassignable: true },
    ]);
    expect(body.querySelector("tr")!.dataset.task).toBe("tc1");
    expect([...body.querySelectorAll("tr:first-child td")].map((td) => td.textContent)).toEqual([
      "pick tc1",
      "offered",
      "cobot1",
      "queued, position 1",
      "",
    ]);
    const button = body.querySelector<HTMLButtonElement>("tr:last-child button[data-reassign]")!;
    expect({ ...button.dataset }).toEqual({ reassign: "8", state: "claimed", label: "place", who: "olivia" });
    expect(body.querySelectorAll("button[data-reassign]")).toHaveLength(1);
    renderWorkRows(body, []);
    expect(body.textContent).toBe("No open tasks.");
  });

  it("puts new events on top of the timeline, once", () => {
    document.body.innerHTML = '<table><tbody><tr data-seq="2"></tr><tr data-seq="1"></tr></tbody></table>';
    const body = document.querySelector("tbody")!;
    const row = (seq: number) =>
      timelineRow(
        { seq, at: "2025-03-01T10:00:00Z", type: "task-completed", task: "t", actor: "o", user: "olivia", marking_before: {}, marking_after: {}, detail: {} },
        { t: "count parts" },
      );
    prependTimeline(body, [row(2), row(3), row(4)]);
    expect([...body.querySelectorAll("tr")].map((tr) => tr.dataset.seq)).toEqual(["4", "3", "2", "1"]);
    expect(body.querySelector("tr")!.textContent).toContain("Task completed");
    expect(body.querySelector("tr")!.textContent).toContain("count parts");
  });

  it("keeps only the newest rows of a timeline that has grown", () => {
    document.body.innerHTML = "<table><tbody></tbody></table>";
    const body = document.querySelector("tbody")!;
    body.innerHTML = [6, 5, 4, 3, 2].map((seq) => `<tr data-seq="${seq}"></tr>`).join("");
    expect(trimTimeline(body, 5)).toBeNull();
    expect(trimTimeline(body, 3)).toBe(4);
    expect([...body.querySelectorAll("tr")].map((tr) => tr.dataset.seq)).toEqual(["6", "5", "4"]);
  });
});
