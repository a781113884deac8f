import { describe, expect, it } from "vitest";
import { asSnapshot, LiveStore } from "../../src/live/store";
import { caseDelta, itemDelta, snapshot, timer, timerDelta } from "./fixtures";

function loaded(): LiveStore {
  const store = new LiveStore();
  store.apply(snapshot());
  return store;
}

describe("applying deltas", () => {
  it("applies the next number and moves the case's seq on", () => {
    const store = loaded();
    expect(store.apply(itemDelta(3, { state: "running", claimed_by: 7 }, "task-started"))).toBe("applied");
    expect(store.state!.workItems.get(100)!.state).toBe("running");
    expect(store.state!.cases.get(10)!.seq).toBe(3);
  });

  it("ignores a delta the snapshot already holds, and one applied twice changes nothing", () => {
    const store = loaded();
    expect(store.apply(itemDelta(2, { state: "withdrawn" }))).toBe("ignored");
    expect(store.state!.workItems.get(100)!.state).toBe("offered");
    store.apply(itemDelta(3, { state: "claimed", claimed_by: 7 }, "task-claimed"));
    const before = JSON.stringify(asSnapshot(store.state!));
    expect(store.apply(itemDelta(3, { state: "claimed", claimed_by: 7 }, "task-claimed"))).toBe("ignored");
    expect(JSON.stringify(asSnapshot(store.state!))).toBe(before);
  });

  it("removes completed items and ended cases with their items", () => {
    const store = loaded();
    store.apply(itemDelta(3, { id: 101, task: "fix" }));
    store.apply(itemDelta(4, { state: "completed" }, "task-completed"));
    expect([...store.state!.workItems.keys()]).toEqual([101]);
    store.apply(caseDelta(10, 5, "completed", "case-completed"));
    expect(store.state!.cases.size).toBe(0);
    expect(store.state!.workItems.size).toBe(0);
    // A late delta of the ended case is old news, not a hole.
    expect(store.apply(itemDelta(4, { state: "completed" }))).toBe("ignored");
    expect(store.hasHoles()).toBe(false);
  });

  it("keeps a cancelled task while its operator may be in the area, until they have left", () => {
    const store = loaded();
    store.apply(itemDelta(3, { state: "running", claimed_by: 7 }, "task-started"));
    store.apply(itemDelta(4, { state: "cancelled", claimed_by: 7, in_area: true }, "task-cancelled"));
    expect(store.state!.workItems.get(100)!.in_area).toBe(true);
    store.apply(itemDelta(5, { state: "cancelled", claimed_by: 7 }, "area-left"));
    expect(store.state!.workItems.has(100)).toBe(false);
  });

  it("starts a new case at seq 1", () => {
    const store = loaded();
    expect(store.apply(caseDelta(11, 1, "running", "case-started"))).toBe("applied");
    expect(store.state!.cases.get(11)!.seq).toBe(1);
  });
});

describe("holes in a case's numbers", () => {
  it("holds a delta that comes before its predecessor and applies both in order", () => {
    const store = loaded();
    const seen: number[] = [];
    store.subscribe((event) => {
      if (event.type === "work-item") seen.push(event.seq);
    });
    expect(store.apply(itemDelta(4, { state: "running", claimed_by: 7 }, "task-started"))).toBe("held");
    expect(store.hasHoles()).toBe(true);
    expect(store.state!.workItems.get(100)!.state).toBe("offered");
    expect(store.apply(itemDelta(3, { state: "claimed", claimed_by: 7 }, "task-claimed"))).toBe("applied");
    expect(store.hasHoles()).toBe(false);
    expect(store.state!.workItems.get(100)!.state).toBe("running");
    expect(seen).toEqual([3, 4]);
  });

  it("takes a case it does not know, starting past 1, for a hole", () => {
    const store = loaded();
    expect(store.apply(itemDelta(6, { id: 200, case: 12 }))).toBe("held");
    expect(store.hasHoles()).toBe(true);
  });

  it("forgets what it held when a new snapshot comes", () => {
    const store = loaded();
    store.apply(itemDelta(9, { state: "running" }));
    store.apply(snapshot({ cases: [{ id: 10, seq: 9, status: "running", name: "", cobots: [] }] }));
    expect(store.hasHoles()).toBe(false);
    expect(store.apply(itemDelta(10, { state: "running", claimed_by: 7 }))).toBe("applied");
  });
});

describe("cobots and the cell", () => {
  it("keeps the newest cobot state and queue", () => {
    const store = loaded();
    const state = {
      cobot: 5, at: 20, reachable: true, robot_mode: "Running", safety_mode: "SAFETY_MODE_NORMAL",
      program_state: "Playing", program: "p", joints: [0, 0, 0, 0, 0, 0], display: "", display_at: 0, error: "",
    };
    store.apply({ type: "cobot-state", states: [state] });
    expect(store.apply({ type: "cobot-state", states: [{ ...state, at: 10, robot_mode: "Idle" }] })).toBe("ignored");
    expect(store.state!.cobots.get(5)!.state!.robot_mode).toBe("Running");
    store.apply({ type: "cobot-queue", queue: { cobot: 5, at: 30, queue_length: 2, current: null, waiting_for: "x" } });
    expect(store.state!.cobots.get(5)!.queue.queue_length).toBe(2);
  });

  it("shows a STOP of its cell and clears it on resume", () => {
    const store = loaded();
    const stop = {
      id: 1, cell: "", at: 1, stopped_by: "olivia", stopped_at: "2026-01-01T00:00:00+00:00",
      resumed_by: "", resumed_at: null, cobots: [5], problems: {},
    };
    store.apply({ type: "cell-stop", stop });
    expect(store.state!.stop?.id).toBe(1);
    expect(store.state!.cobots.get(5)!.stopped).toBe(true);
    store.apply({ type: "cell-stop", stop: { ...stop, resumed_at: "2026-01-01T00:01:00+00:00", resumed_by: "olivia" } });
    expect(store.state!.stop).toBeNull();
    expect(store.state!.cobots.get(5)!.stopped).toBe(false);
  });
});

describe("the timers a case waits for", () => {
  it("adds an armed timer and drops it when it fires or is disarmed, from the deltas alone", () => {
    const store = loaded();
    expect(store.apply(timerDelta(3, "timer-armed"))).toBe("applied");
    store.apply(timerDelta(4, "timer-armed", { transition: "reminder", due_at: "2026-01-01T10:00:00+00:00" }));
    expect(asSnapshot(store.state!).timers.map((t) => t.transition)).toEqual(["reminder", "late"]);
    store.apply(timerDelta(5, "timer-fired", { transition: "reminder", due_at: "2026-01-01T10:00:00+00:00" }));
    expect(asSnapshot(store.state!).timers.map((t) => t.transition)).toEqual(["late"]);
    expect(store.state!.cases.get(10)!.seq).toBe(5);
    store.apply(timerDelta(6, "timer-disarmed"));
    expect(store.state!.timers.size).toBe(0);
  });

  it("takes the armed timers from the snapshot, and forgets them when their case ends", () => {
    const store = new LiveStore();
    store.apply(snapshot({ timers: [timer()] }));
    expect([...store.state!.timers.values()]).toEqual([timer()]);
    store.apply(caseDelta(10, 3, "cancelled", "case-cancelled"));
    expect(store.state!.timers.size).toBe(0);
  });

  it("holds a timer delta that comes before the one it follows", () => {
    const store = loaded();
    expect(store.apply(timerDelta(4, "timer-fired"))).toBe("held");
    expect(store.apply(timerDelta(3, "timer-armed"))).toBe("applied");
    expect(store.state!.timers.size).toBe(0);
  });
});
