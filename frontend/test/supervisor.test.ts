import { describe, expect, it } from "vitest";

import { ApiError, problemOf, refusalMessage } from "../src/shared/http";
import type { EventJson, IncidentJson, WorkItemJson } from "../src/supervisor/api";
import type { LiveEvent } from "../src/live/events";
import {
  POLL_MS,
  SAFETY_POLL_MS,
  concernsCase,
  concernsIncidents,
  pollInterval,
  constraintTokens,
  formatTime,
  markingChange,
  outcomeText,
  prettyJson,
  resolveBody,
  taskStates,
  timelineRow,
  tokenText,
  touchesInterruptions,
  unseenEvents,
  workRow,
} from "../src/supervisor/model";

function item(task: string, state: string, extra: Partial<WorkItemJson> = {}): WorkItemJson {
  return { id: 1, task, label: "", actor: "o", kind: "operator", state, claimed_by: null, job: null, ...extra };
}

function incident(extra: Partial<IncidentJson> = {}): IncidentJson {
  return {
    id: 7,
    case: 3,
    work_item: 11,
    task: "tc1",
    kind: "step-failed",
    message: "Protective stop",
    cobot_state: null,
    opened_at: "2025-03-01T10:00:00Z",
    resolved_at: null,
    resolution: "",
    resolved_by: null,
    ...extra,
  };
}

function event(seq: number, extra: Partial<EventJson> = {}): EventJson {
  return {
    seq,
    at: "2025-03-01T10:00:05.123456Z",
    type: "task-started",
    task: "to1",
    actor: "o",
    user: null,
    marking_before: {},
    marking_after: {},
    detail: {},
    ...extra,
  };
}

describe("the marking on the net", () => {
  it("draws no token as nothing, one as a dot and more as the number", () => {
    expect([0, 1, 2, 12].map(tokenText)).toEqual(["", "●", "2", "12"]);
  });

  it("counts a constraint's tokens over its places", () => {
    expect(constraintTokens(["func-start:a>b", "func-done:b>a"], { "func-done:b>a": 1, p1: 4 })).toBe(1);
    expect(constraintTokens([], { p1: 1 })).toBe(0);
  });

  it("puts an open incident before running before offered", () => {
    const marking = { "running:to1": 1, "running:tc1": 1 };
    const states = taskStates(
      ["to1", "tc1", "to2", "to3"],
      marking,
      [item("to2", "offered"), item("to3", "completed"), item("to1", "running")],
      [incident({ task: "tc1" })],
    );
    expect(Object.fromEntries(states)).toEqual({ to1: "running", tc1: "incident", to2: "offered", to3: "" });
  });

  it("counts a claimed task as offered: nobody has started it", () => {
    expect(taskStates(["t"], {}, [item("t", "claimed")], []).get("t")).toBe("offered");
  });
});

describe("the timeline", () => {
  it("says what an event did to the marking, place by place in order", () => {
    expect(markingChange({ p1: 1, q: 2 }, { p2: 1, q: 2, "running:t": 1 })).toEqual(["p1 −1", "p2 +1", "running:t +1"]);
    expect(markingChange({ p: 3 }, { p: 1 })).toEqual(["p −2"]);
  });

  it("prints times in UTC to the second, as the server does", () => {
    expect(formatTime("2025-03-01T10:00:05.987654+01:00")).toBe("2025-03-01 09:00:05");
    expect(formatTime("not a time")).toBe("not a time");
  });

  it("names the user, else the pattern actor, else hrc", () => {
    expect(timelineRow(event(1, { user: "olivia" }), {}).who).toBe("olivia");
    expect(timelineRow(event(2, { user: null, actor: "c" }), {}).who).toBe("c");
    expect(timelineRow(event(3, { user: null, actor: "" }), {}).who).toBe("hrc");
  });

  it("makes a row with the task's label, the change and the detail", () => {
    const row = timelineRow(
      event(4, {
        type: "incident-resolved",
        task: "tc1",
        marking_before: { p2: 1 },
        marking_after: { "running:tc1": 1 },
        detail: { resolution: "retry", incident: 3, extra: { b: 1, a: [1, 2] } },
      }),
      { tc1: "place insert" },
    );
    expect(row).toMatchObject({
      seq: 4,
      what: "Incident resolved",
      taskLabel: "place insert",
      change: "p2 −1, running:tc1 +1",
      detail: 'resolution: retry, incident: 3, extra: {"a":[1,2],"b":1}',
      when: "2025-03-01 10:00:05",
    });
  });

  it("keeps an unknown event type as it is", () => {
    expect(timelineRow(event(1, { type: "something-new" }), {}).what).toBe("something-new");
  });

  it("shows only events after the last one shown, oldest first, each once", () => {
    const events = [event(7), event(5), event(6), event(7), event(4)];
    expect(unseenEvents(5, events).map((e) => e.seq)).toEqual([6, 7]);
  });

  it("knows which events change the interruptions", () => {
    expect(touchesInterruptions([event(1), event(2, { type: "task-resumed" })])).toBe(true);
    expect(touchesInterruptions([event(1)])).toBe(false);
  });
});

describe("open tasks", () => {
  const job = { cobot_name: "cobot1", device_name: null, state: "queued", queue_position: 2, waiting_for: "", attempt: 1, last_error: "" };

  it("says where a cobot's job stands", () => {
    expect(workRow(item("tc1", "offered", { label: "pick", job })).job).toBe("queued, position 2");
    expect(workRow(item("tc1", "offered", { job: { ...job, waiting_for: "a completion of to1" } })).job).toBe(
      "queued, position 2; waiting for a completion of to1",
    );
    expect(workRow(item("tc1", "running", { job: { ...job, state: "running", attempt: 2 } })).job).toBe(
      "running, attempt 2",
    );
    expect(workRow(item("tc1", "running", { job: { ...job, state: "failed", last_error: "stop" } })).job).toBe(
      "failed: stop",
    );
  });

  it("names who has the task: the operator who claimed it, else the cobot", () => {
    expect(workRow(item("t", "claimed", { claimed_by: "olivia" })).who).toBe("olivia");
    expect(workRow(item("tc1", "offered", { job })).who).toBe("cobot1");
    expect(workRow(item("t", "offered"))).toMatchObject({ who: "–", label: "t", job: "" });
  });

  it("names the device a device call waits for", () => {
    const call = { ...job, cobot_name: null, device_name: "axis1", queue_position: 1 };
    expect(workRow(item("ta1", "offered", { kind: "device", job: call }))).toMatchObject({
      who: "axis1",
      job: "queued, position 1",
    });
  });

  it("offers to hand over an operator task, never a cobot's", () => {
    expect(["offered", "claimed", "running"].map((state) => workRow(item("t", state)).reassignable)).toEqual([
      true,
      true,
      true,
    ]);
    expect(workRow(item("tc1", "offered", { kind: "step", job })).reassignable).toBe(false);
    expect(workRow(item("t", "completed")).reassignable).toBe(false);
  });
});

describe("resolving an incident", () => {
  it("sends retry with whether to run the step again", () => {
    expect(resolveBody("retry", { again: true, outputs: "nonsense" })).toEqual({
      ok: true,
      value: { resolution: "retry", again: true },
    });
  });

  it("sends skip with its outputs as an object", () => {
    expect(resolveBody("skip", { again: false, outputs: ' {"placed": true} ' })).toEqual({
      ok: true,
      value: { resolution: "skip", outputs: { placed: true } },
    });
    expect(resolveBody("skip", { again: false, outputs: "  " })).toEqual({
      ok: true,
      value: { resolution: "skip", outputs: {} },
    });
  });

  it("refuses outputs that are not JSON, or not an object, with a message", () => {
    const broken = resolveBody("skip", { again: false, outputs: "{placed: true}" });
    expect(broken.ok).toBe(false);
    expect(!broken.ok && broken.message).toMatch(/^The outputs are not JSON: /);
    for (const text of ["[1]", "3", "null", '"x"']) {
      expect(resolveBody("skip", { again: false, outputs: text })).toEqual({
        ok: false,
        message: 'The outputs must be a JSON object, such as {"placed": true}.',
      });
    }
  });

  it("sends cancel alone", () => {
    expect(resolveBody("cancel", { again: true, outputs: "{}" })).toEqual({ ok: true, value: { resolution: "cancel" } });
  });

  it("says how it was resolved, and by whom", () => {
    expect(outcomeText(incident())).toBe("");
    expect(outcomeText(incident({ resolved_at: "2025-03-01T10:01:00Z", resolution: "skip", resolved_by: "erik" }))).toBe(
      "Resolved: skip by erik",
    );
  });

  it("shows the API's message for a refusal", () => {
    expect(refusalMessage(409, { detail: "pick is an operator task: there is nothing to retry." })).toBe(
      "pick is an operator task: there is nothing to retry.",
    );
    expect(refusalMessage(502, null)).toBe("The server answered 502.");
    expect(refusalMessage(0, null)).toBe("The server cannot be reached.");
    expect(new ApiError(403, "no").status).toBe(403);
    expect(problemOf(new ApiError(409, "count parts has started: name who finishes it."))).toBe(
      "count parts has started: name who finishes it.",
    );
    expect(problemOf(new TypeError("bad"))).toBe("TypeError: bad");
  });
});

describe("JSON on the page", () => {
  it("is indented with sorted keys, as the server prints it", () => {
    expect(prettyJson({ b: 1, a: { d: [2], c: true } })).toBe(
      '{\n  "a": {\n    "c": true,\n    "d": [\n      2\n    ]\n  },\n  "b": 1\n}',
    );
  });
});

describe("the live socket as a doorbell", () => {
  const delta = (type: "case" | "work-item" | "incident", caseId: number) => ({ type, case: caseId, seq: 4 }) as unknown as LiveEvent;
  const snapshot = { type: "snapshot" } as unknown as LiveEvent;
  const cobotState = { type: "cobot-state", states: [] } as unknown as LiveEvent;

  it("rings a case page for its own case's deltas and every snapshot", () => {
    expect(concernsCase(delta("work-item", 3), 3)).toBe(true);
    expect(concernsCase(delta("incident", 3), 3)).toBe(true);
    expect(concernsCase(delta("case", 3), 3)).toBe(true);
    expect(concernsCase(delta("case", 4), 3)).toBe(false);
    expect(concernsCase(cobotState, 3)).toBe(false);
    expect(concernsCase(snapshot, 3)).toBe(true);
  });

  it("rings the incidents page for incidents of any case", () => {
    expect(concernsIncidents(delta("incident", 9))).toBe(true);
    expect(concernsIncidents(delta("work-item", 9))).toBe(false);
    expect(concernsIncidents(snapshot)).toBe(true);
  });

  it("polls fast unless every socket is live", () => {
    expect(pollInterval([])).toBe(POLL_MS);
    expect(pollInterval(["live", "reconnecting"])).toBe(POLL_MS);
    expect(pollInterval(["live", "live"])).toBe(SAFETY_POLL_MS);
    expect(SAFETY_POLL_MS).toBeGreaterThan(POLL_MS);
  });
});
