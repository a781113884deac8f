import { expect, test } from "vitest";

import { type CancelTarget, cancelsOf, parseCancels, renamedCancels } from "../../src/editor/model/cancels";

const NODES: Record<string, CancelTarget> = {
  p3: { kind: "place", process: "N" },
  tc2: { kind: "task", process: "N" },
  t1: { kind: "silent", process: "N" },
  p9: { kind: "place", process: "N2" },
};
const lookup = (id: string) => NODES[id];

test("cancels lists places and tasks of the transition's net, each once, in the order written", () => {
  expect(parseCancels("p3, tc2", "N", lookup)).toEqual(["p3", "tc2"]);
  expect(parseCancels(" tc2 p3;tc2 ", "N", lookup)).toEqual(["tc2", "p3"]);
  expect(parseCancels("  ", "N", lookup)).toEqual([]);
});

test("every id that cannot be cancelled is named with why, in one message", () => {
  expect(() => parseCancels("p3, nope, t1, p9", "N", lookup)).toThrowError(
    "Cannot cancel: nope is no place or task of this pattern; t1 is a silent transition, which never runs; p9 is in net N2, not in this transition's net N.",
  );
});

test("the list is read from the document and follows a renamed node", () => {
  expect(cancelsOf({ cancels: ["p3", 4, "tc2"] })).toEqual(["p3", "tc2"]);
  expect(cancelsOf({ cancels: "p3" })).toEqual([]);
  expect(renamedCancels({ cancels: ["p3", "tc2"] }, "tc2", "drill")).toEqual(["p3", "drill"]);
  expect(renamedCancels({ cancels: ["p3"] }, "tc2", "drill")).toBeNull();
});
