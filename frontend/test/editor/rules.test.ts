import { describe, expect, test } from "vitest";

import {
  arcRefusal,
  constraintRefusal,
  laneRemovalRefusal,
  newTaskRefusal,
  type NodeInfo,
  performerRefusal,
} from "../../src/editor/model/rules";

const p1: NodeInfo = { id: "p1", kind: "place", process: "N" };
const p2: NodeInfo = { id: "p2", kind: "place", process: "N" };
const t1: NodeInfo = { id: "t1", kind: "transition", process: "N" };
const tc1: NodeInfo = { id: "tc1", kind: "transition", performer: "c", process: "N" };
const tc2: NodeInfo = { id: "tc2", kind: "transition", performer: "c", process: "N" };
const to1: NodeInfo = { id: "to1", kind: "transition", performer: "o", process: "N" };
const elsewhere: NodeInfo = { id: "p21", kind: "place", process: "N2" };

describe("arcs", () => {
  test("join a place and a transition, either way", () => {
    expect(arcRefusal(p1, tc1, [])).toBeNull();
    expect(arcRefusal(tc1, p1, [])).toBeNull();
  });

  test("never two places", () => {
    expect(arcRefusal(p1, p2, [])).toBe("An arc cannot join two places (p1 → p2): put a transition between them.");
  });

  test("never two transitions", () => {
    expect(arcRefusal(t1, tc1, [])).toBe("An arc cannot join two transitions (t1 → tc1): put a place between them.");
  });

  test("stay inside one net", () => {
    expect(arcRefusal(elsewhere, tc1, [])).toBe("p21 is in net N2 and tc1 in net N: an arc stays inside one net.");
  });

  test("are drawn once", () => {
    expect(arcRefusal(p1, tc1, [{ source: "p1", target: "tc1" }])).toBe("There is already an arc from p1 to tc1.");
    expect(arcRefusal(tc1, p1, [{ source: "p1", target: "tc1" }])).toBeNull();
  });
});

describe("constraints", () => {
  test("join tasks of different actors, in the order drawn", () => {
    expect(constraintRefusal(to1, tc1, "time", [])).toBeNull();
    expect(constraintRefusal(tc1, to1, "func", [{ from: "to1", to: "tc1", type: "time" }])).toBeNull();
  });

  test("never within one actor", () => {
    expect(constraintRefusal(tc1, tc2, "time", [])).toBe("tc1 and tc2 are both tasks of c: a constraint joins tasks of different actors.");
  });

  test("never on a place or a silent transition", () => {
    expect(constraintRefusal(p1, tc1, "space", [])).toBe("A constraint joins two tasks; p1 is a place.");
    expect(constraintRefusal(to1, t1, "space", [])).toBe("t1 is a silent transition: only a task (a transition with an actor) can be constrained.");
  });

  test("never a task with itself", () => {
    expect(constraintRefusal(tc1, tc1, "time", [])).toBe("A constraint joins two different tasks; tc1 cannot constrain itself.");
  });

  test("of a kind the format knows, once", () => {
    expect(constraintRefusal(to1, tc1, "order", [])).toBe('Unknown constraint type "order": use time, space or func.');
    expect(constraintRefusal(to1, tc1, "time", [{ from: "to1", to: "tc1", type: "time" }])).toBe("There is already a time constraint from to1 to tc1.");
  });

  test("of one type per ordered pair of tasks", () => {
    expect(constraintRefusal(to1, tc1, "space", [{ from: "to1", to: "tc1", type: "time" }])).toBe(
      "There is already a time constraint from to1 to tc1: an ordered pair of tasks has one constraint type (change that one's type instead).",
    );
  });
});

describe("actors and lanes", () => {
  const constraints = [{ from: "to1", to: "tc1", type: "time" }];
  const performerOf = (task: string) => ({ tc1: "c", to1: "o" })[task];

  test("a task cannot join the actor of a task it is constrained with", () => {
    expect(performerRefusal("to1", "c", constraints, performerOf)).toBe(
      "to1 cannot become a task of c: its time constraint with tc1 (a task of c) must join tasks of different actors.",
    );
    expect(performerRefusal("to1", "o2", constraints, performerOf)).toBeNull();
  });

  test("a task needs a lane", () => {
    expect(performerRefusal("to1", null, constraints, performerOf)).toBe("A task belongs to an actor: put to1 inside an actor's lane.");
    expect(newTaskRefusal(null, 0)).toBe("Add an operator or cobot lane first: every task belongs to an actor.");
    expect(newTaskRefusal(null, 2)).toBe("A task belongs to an actor: drop it inside an actor's lane.");
    expect(newTaskRefusal("o", 2)).toBeNull();
  });

  test("a lane with tasks is not deleted", () => {
    expect(laneRemovalRefusal("o", ["to1", "to2"])).toBe("The lane of o still holds tasks to1, to2: delete them or move them to another lane first.");
    expect(laneRemovalRefusal("o", [])).toBeNull();
  });
});
