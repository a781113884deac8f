import { describe, expect, test } from "vitest";

import { type ExecutionNet, heldBackWords, readExecutionNet, TokenGame } from "../../src/editor/model/net";

/**
 * The execution net of: p0 → t1 (silent split) → p1 → to1 (operator) → p2 → tc1 (cobot) → p3,
 * with a time constraint `to1 → tc1` — as POST /api/patterns/execution-net/ answers it.
 */
function handOver(constraint: "to1>tc1" | "tc1>to1" = "to1>tc1"): ExecutionNet {
  const [a, b] = constraint.split(">");
  return readExecutionNet({
    places: [
      { id: "p0", label: "p0", tokens: 1, kind: "flow", of: "p0" },
      { id: "p1", label: "p1", tokens: null, kind: "flow", of: "p1" },
      { id: "p2", label: "p2", tokens: 0, kind: "flow", of: "p2" },
      { id: "p3", label: "p3", tokens: 0, kind: "flow", of: "p3" },
      { id: "running:to1", label: "to1 running", tokens: 0, kind: "busy", of: "to1" },
      { id: "running:tc1", label: "tc1 running", tokens: 0, kind: "busy", of: "tc1" },
      { id: `time:${a}>${b}`, label: `${a} done, for ${b}`, tokens: null, kind: "constraint", of: { constraint: 0, type: "time", role: "time", from: a, to: b } },
    ],
    transitions: [
      { id: "t1", label: "t1", kind: "silent", task: "t1" },
      { id: "start:to1", label: "start to1", kind: "start", task: "to1", performer: "o" },
      { id: "complete:to1", label: "complete to1", kind: "complete", task: "to1", performer: "o" },
      { id: "start:tc1", label: "start tc1", kind: "start", task: "tc1", performer: "c" },
      { id: "complete:tc1", label: "complete tc1", kind: "complete", task: "tc1", performer: "c" },
    ],
    arcs: [
      ["p0", "t1"], ["t1", "p1"],
      ["p1", "start:to1"], ["start:to1", "running:to1"], ["running:to1", "complete:to1"], ["complete:to1", "p2"],
      ["p2", "start:tc1"], ["start:tc1", "running:tc1"], ["running:tc1", "complete:tc1"], ["complete:tc1", "p3"],
      [`complete:${a}`, `time:${a}>${b}`], [`time:${a}>${b}`, `start:${b}`],
    ],
    initial: { p0: 1 },
    final: { p3: 1 },
    ignored: [`time:${a}>${b}`],
  });
}

const labels = (game: TokenGame) => game.enabled().map((t) => t.label);

describe("the token game", () => {
  test("fires the initial marking's enabled transitions only", () => {
    const game = new TokenGame(handOver());
    expect(game.net.places.find((place) => place.kind === "constraint")?.of).toEqual(["to1", "tc1"]);
    expect(labels(game)).toEqual(["t1"]);
    expect(() => game.fire("start:to1")).toThrowError("start to1 is not enabled.");
  });

  test("a click on a task starts it, a second click completes it", () => {
    const game = new TokenGame(handOver());
    game.fire(game.firingFor("t1")!.id);
    expect(game.firingFor("to1")?.label).toBe("start to1");
    game.fire("start:to1");
    expect(game.isRunning("to1")).toBe(true);
    expect(game.firingFor("to1")?.label).toBe("complete to1");
    game.fire("complete:to1");
    expect(game.isRunning("to1")).toBe(false);
    expect(game.tokens("p2")).toBe(1);
    expect(game.tokens("time:to1>tc1")).toBe(1);
  });

  test("a time constraint holds the second task until the first completed", () => {
    const game = new TokenGame(handOver("tc1>to1"));
    game.fire("t1");
    expect(labels(game)).toEqual([]);
    expect(game.firingFor("to1")).toBeNull();
  });

  test("steps back and forward through the firings", () => {
    const game = new TokenGame(handOver());
    for (const id of ["t1", "start:to1", "complete:to1"]) game.fire(id);
    expect(game.back()).toBe(true);
    expect(game.back()).toBe(true);
    expect(game.isRunning("to1")).toBe(false);
    expect(game.tokens("p1")).toBe(1);
    expect(game.forward()).toBe(true);
    expect(game.isRunning("to1")).toBe(true);
    game.fire("complete:to1");
    expect(game.forward()).toBe(false);
    expect(game.history.map((t) => t.label)).toEqual(["t1", "start to1", "complete to1"]);
    game.back();
    game.back();
    game.back();
    expect(game.back()).toBe(false);
    expect([...game.marking]).toEqual([["p0", 1]]);
  });

  test("runs randomly until nothing is enabled, and the case ends in the sink", () => {
    const game = new TokenGame(handOver());
    let fired = 0;
    while (game.fireRandom(() => 0.5)) fired += 1;
    expect(fired).toBe(5);
    expect([...game.marking]).toEqual([["p3", 1]]);
  });

  test("a witness is replayed step by step and can be stepped back", () => {
    const game = new TokenGame(handOver());
    game.load(["t1", "start to1", "complete to1"]);
    expect(game.future).toHaveLength(3);
    expect(game.forward()).toBe(true);
    expect(game.forward()).toBe(true);
    expect(game.isRunning("to1")).toBe(true);
    expect(game.back()).toBe(true);
    expect(game.future.map((t) => t.label)).toEqual(["start to1", "complete to1"]);
    expect(game.forward() && game.forward()).toBe(true);
    expect(game.forward()).toBe(false);
    expect(game.tokens("p2")).toBe(1);
  });

  test("a witness naming a firing the net does not have is refused", () => {
    expect(() => new TokenGame(handOver()).load(["start tc9"])).toThrowError("The witness names start tc9, which is not in the execution net.");
  });
});

describe("a transition that cancels", () => {
  /** p0 → t1 → p1 → to1 → p2, and t1 arms a boundary step tb that cancels to1 (its place and its run). */
  function boundary(): ExecutionNet {
    return readExecutionNet({
      places: [
        { id: "p0", tokens: 1 }, { id: "p1" }, { id: "armed" }, { id: "p2" },
        { id: "running:to1", kind: "busy", of: "to1" },
      ],
      transitions: [
        { id: "t1", kind: "silent", task: "t1" },
        { id: "start:to1", kind: "start", task: "to1", performer: "o" },
        { id: "complete:to1", kind: "complete", task: "to1", performer: "o" },
        { id: "tb", kind: "silent", task: "tb", resets: ["p1", "running:to1"] },
      ],
      arcs: [["p0", "t1"], ["t1", "p1"], ["t1", "armed"], ["p1", "start:to1"], ["start:to1", "running:to1"], ["running:to1", "complete:to1"], ["complete:to1", "p2"], ["armed", "tb"], ["tb", "p2"]],
    });
  }

  test("empties its reset places when it fires, a running task included", () => {
    const game = new TokenGame(boundary());
    expect(game.net.transitions.map((t) => t.resets)).toEqual([[], [], [], ["p1", "running:to1"]]);
    for (const id of ["t1", "start:to1", "tb"]) game.fire(id);
    expect(game.isRunning("to1")).toBe(false);
    expect([...game.marking]).toEqual([["p2", 1]]);
  });

  test("a step back puts back what it took, and forward takes it again", () => {
    const game = new TokenGame(boundary());
    for (const id of ["t1", "start:to1", "tb"]) game.fire(id);
    game.back();
    expect(game.isRunning("to1")).toBe(true);
    expect(new Map(game.marking)).toEqual(new Map([["running:to1", 1], ["armed", 1]]));
    game.back();
    game.fire("tb");
    expect([...game.marking]).toEqual([["p2", 1]]);
    game.back();
    expect(new Map(game.marking)).toEqual(new Map([["p1", 1], ["armed", 1]]));
  });
});

describe("a task held back by a constraint", () => {
  const names: Record<string, string> = { to1: "“Press the button”", tc1: "“Move part”" };
  const name = (id: string) => names[id] ?? id;

  test("says which constraint and which other actor's task it waits for", () => {
    // tc1 -> to1: the operator's to1 waits for the cobot's tc1, which comes later in the flow.
    const game = new TokenGame(handOver("tc1>to1"));
    game.fire("t1");

    expect(game.firingFor("to1")).toBeNull();
    expect(game.heldBack("to1").map((place) => place.id)).toEqual(["time:tc1>to1"]);
    expect(heldBackWords(game, "to1", name)).toBe(
      "“Press the button” cannot start yet, held back by the time constraint “Move part” → “Press the button”: it waits for c's “Move part” to complete.",
    );
  });

  test("a task that waits for its flow is not held back by a constraint", () => {
    const game = new TokenGame(handOver());

    expect(game.heldBack("tc1")).toEqual([]);
    expect(heldBackWords(game, "tc1", name)).toBe("");
  });
});

describe("reading the server's execution net", () => {
  test("fills in kinds and owners from the ids when the answer leaves them out", () => {
    const net = readExecutionNet({
      places: [{ id: "running:tc1", initial: 0 }, { id: "time:a>b" }, { id: "p1", tokens: 1 }],
      transitions: [{ id: "start:tc1" }, { id: "t2" }],
      arcs: [{ source: "p1", target: "start:tc1", weight: 2 }],
    });
    expect(net.places.map((p) => [p.id, p.kind, p.of])).toEqual([
      ["running:tc1", "busy", ["tc1"]],
      ["time:a>b", "constraint", ["a", "b"]],
      ["p1", "flow", ["p1"]],
    ]);
    expect(net.transitions.map((t) => [t.label, t.kind, t.task])).toEqual([
      ["start tc1", "start", "tc1"],
      ["t2", "silent", "t2"],
    ]);
    expect(net.arcs).toEqual([["p1", "start:tc1"], ["p1", "start:tc1"]]);
  });

  test("refuses an answer without places", () => {
    expect(() => readExecutionNet({ detail: "nope" })).toThrowError("The server's execution net has no places or transitions.");
  });
});
