import { describe, expect, it } from "vitest";
import type { Snapshot } from "../../src/live/events";
import { type LiveState, LiveStore } from "../../src/live/store";
import {
  atThisCell,
  cellsOf,
  cellWords,
  cobotWork,
  elsewhere,
  myTasks,
  nextAction,
  teamTasks,
  timersOf,
  waitingLine,
  waitingTimers,
  withDisplayMessages,
} from "../../src/tablet/view";
import { item, snapshot, timer } from "../live/fixtures";

const WELD_ARM = {
  id: 5,
  name: "weld-arm",
  cell: "weld",
  stopped: false,
  state: null,
  queue: { cobot: 5, at: 1, queue_length: 0, current: null, waiting_for: "" },
};

/** Three cases: 10 uses the weld cell's cobot, 11 a cobot of another cell (not sent to a weld
 * tablet), 12 no cobot at all. Each has one task offered to the user by name (101, 111, 121). */
function floor(cell: string, overrides: Partial<Snapshot> = {}): LiveState {
  const store = new LiveStore();
  store.apply(
    snapshot({
      cell,
      cases: [
        { id: 10, seq: 2, status: "running", name: "Weld", cobots: [5] },
        { id: 11, seq: 2, status: "running", name: "Paint", cobots: [6] },
        { id: 12, seq: 2, status: "running", name: "Count", cobots: [] },
      ],
      work_items: [item({ id: 101, case: 10 }), item({ id: 111, case: 11 }), item({ id: 121, case: 12 })],
      cobots: cell ? [WELD_ARM] : [WELD_ARM, { ...WELD_ARM, id: 6, name: "paint-arm", cell: "paint" }],
      floor: [
        { id: 5, name: "weld-arm", cell: "weld" },
        { id: 6, name: "paint-arm", cell: "paint" },
      ],
      ...overrides,
    }),
  );
  return store.state!;
}

const ids = (items: Array<{ id: number }>): number[] => items.map((i) => i.id);

describe("a cell's tablet", () => {
  it("offers the tasks of its cell's cases and of cases with no cobot, not those of other cells", () => {
    const state = floor("weld");
    expect(ids(myTasks(state))).toEqual([101, 121]);
    expect(atThisCell(state, state.workItems.get(111)!)).toBe(false);
    expect(ids(elsewhere(state))).toEqual([111]);
    expect(cellsOf(state, elsewhere(state))).toEqual(["paint"]);
  });

  it("keeps a task the user holds in another cell: theirs to finish", () => {
    const state = floor("weld", {
      work_items: [item({ id: 111, case: 11, state: "running", claimed_by: 7, candidates: [7] })],
    });
    expect(ids(myTasks(state))).toEqual([111]);
    expect(cellsOf(state, myTasks(state))).toEqual(["paint"]);
    expect(elsewhere(state)).toEqual([]);
  });

  it("names no cell for a case whose cobots it does not know, or that stand in no cell", () => {
    const state = floor("weld", {
      cases: [
        { id: 11, seq: 2, status: "running", name: "Paint", cobots: [6, 9] },
        { id: 13, seq: 2, status: "running", name: "New", cobots: [9] },
      ],
      work_items: [item({ id: 111, case: 11 }), item({ id: 131, case: 13 })],
      floor: [{ id: 6, name: "paint-arm", cell: "paint" }],
    });
    expect(ids(elsewhere(state))).toEqual([111, 131]);
    expect(cellsOf(state, [state.workItems.get(131)!])).toEqual([]);
    expect(cellsOf(state, elsewhere(state))).toEqual(["paint"]);
  });

  it("scopes team tasks the same way, and counts them among those waiting elsewhere", () => {
    const team = { candidates: [], team: 3 };
    const state = floor("weld", {
      work_items: [item({ id: 101, case: 10, ...team }), item({ id: 111, case: 11, ...team })],
    });
    expect(ids(teamTasks(state))).toEqual([101]);
    expect(ids(myTasks(state))).toEqual([]);
    expect(ids(elsewhere(state))).toEqual([111]);
  });

  it("does not count what someone else took or what is not offered to the user", () => {
    const state = floor("weld", {
      work_items: [item({ id: 111, case: 11, state: "claimed", claimed_by: 8 }), item({ id: 112, case: 11, candidates: [8] })],
    });
    expect(elsewhere(state)).toEqual([]);
  });
});

describe("the whole floor's tablet", () => {
  it("offers every case's tasks and has nothing elsewhere", () => {
    const state = floor("");
    expect(ids(myTasks(state))).toEqual([101, 111, 121]);
    expect(elsewhere(state)).toEqual([]);
  });
});

describe("cell words", () => {
  it("name one cell, several, or none known", () => {
    expect(cellWords(["paint"])).toBe("the paint cell");
    expect(cellWords(["assembly", "paint", "weld"], true)).toBe("the assembly, paint and weld cells");
    expect(cellWords([])).toBe("another cell");
    expect(cellWords([], true)).toBe("other cells");
  });
});

describe("a task card's cobots", () => {
  const busy = (caseId: number, extra: object = {}) => ({
    ...WELD_ARM,
    ...extra,
    queue: {
      ...WELD_ARM.queue,
      queue_length: 1,
      current: { case: caseId, work_item: 900, task: "tc1", label: "weld the seam", kind: "step", step: 2, attempt: 1 },
    },
  });
  const state = (cobot: object) =>
    floor("weld", {
      cases: [
        { id: 10, seq: 2, status: "running", name: "Weld", cobots: [5] },
        { id: 14, seq: 2, status: "running", name: "Weld", cobots: [5] },
      ],
      work_items: [item({ id: 101, case: 10 })],
      cobots: [cobot as typeof WELD_ARM],
    });

  it("list the cobot's work for the task's own case", () => {
    const here = state(busy(10));
    expect(cobotWork(here, here.workItems.get(101)!)).toEqual(["weld-arm: weld the seam (step 2), case 10"]);
  });

  it("do not list the cobot's work for another case", () => {
    const there = state(busy(14));
    expect(cobotWork(there, there.workItems.get(101)!)).toEqual(["weld-arm: busy with another case"]);
  });

  it("still say the cobot is held by a STOP while it serves another case", () => {
    const stopped = state(busy(14, { stopped: true }));
    expect(cobotWork(stopped, stopped.workItems.get(101)!)).toEqual(["weld-arm: held by STOP"]);
  });
});

describe("display messages", () => {
  const showing = (display: string, display_at: number, at: number) => ({
    ...WELD_ARM,
    state: {
      cobot: 5, at, reachable: true, robot_mode: "Running", safety_mode: "SAFETY_MODE_NORMAL",
      program_state: "Playing", program: "p", joints: [], display, display_at, error: "",
    },
  });

  it("keep the time a text appeared, however often its state is sent again", () => {
    let messages = withDisplayMessages([], [showing("Place the part", 100, 100)], 20);
    messages = withDisplayMessages(messages, [showing("Place the part", 100, 130)], 20); // joints moved
    expect(messages).toEqual([{ cobot: 5, name: "weld-arm", text: "Place the part", at: 100 }]);
  });

  it("do not come back as new after the state was lost and a snapshot brings it again", () => {
    let messages = withDisplayMessages([], [showing("Place the part", 100, 100)], 20);
    messages = withDisplayMessages(messages, [{ ...WELD_ARM, state: null }], 20); // expired, reconnecting
    messages = withDisplayMessages(messages, [showing("Place the part", 100, 400)], 20); // the snapshot
    expect(messages.map((m) => m.at)).toEqual([100]);
  });

  it("add a new text, newest first, and the same text shown again later as a new message", () => {
    let messages = withDisplayMessages([], [showing("Place the part", 100, 100)], 20);
    messages = withDisplayMessages(messages, [showing("Take the part", 150, 150)], 20);
    messages = withDisplayMessages(messages, [showing("Place the part", 200, 200)], 2);
    expect(messages.map((m) => [m.text, m.at])).toEqual([
      ["Place the part", 200],
      ["Take the part", 150],
    ]);
  });
});

describe("a cancelled task whose operator may be in the area", () => {
  it("asks its operator, and nobody else, to say they have left", () => {
    const state = floor("");
    const cancelled = item({ id: 101, case: 10, state: "cancelled", claimed_by: 7, in_area: true });
    expect(nextAction(state, cancelled)).toBe("left-area");
    expect(nextAction(state, { ...cancelled, claimed_by: 8 })).toBeNull();
    expect(nextAction(state, { ...cancelled, in_area: false })).toBeNull();
  });
});

describe("the timers a case waits for", () => {
  it("reads 'waiting until HH:MM:SS (label)' in the tablet's local time", () => {
    const due = new Date(2026, 0, 1, 9, 5, 7); // local time
    expect(waitingLine(timer({ due_at: due.toISOString() }))).toBe("waiting until 09:05:07 (Too late)");
    expect(waitingLine(timer({ due_at: due.toISOString(), label: "" }))).toBe("waiting until 09:05:07 (late)");
  });

  it("lists a case's timers on its cards, and the cell's cases' timers apart", () => {
    const timers = [
      timer({ case: 10, transition: "b", due_at: "2026-01-01T10:00:02+00:00" }),
      timer({ case: 10, transition: "a", due_at: "2026-01-01T10:00:01+00:00" }),
      timer({ case: 11, transition: "c" }),
    ];
    const weld = floor("weld", { timers });
    expect(timersOf(weld, 10).map((t) => t.transition)).toEqual(["a", "b"]);
    expect(waitingTimers(weld).map((t) => t.transition)).toEqual(["a", "b"]); // case 11 paints
    expect(waitingTimers(floor("", { timers })).map((t) => t.transition)).toEqual(["a", "b", "c"]);
  });
});
