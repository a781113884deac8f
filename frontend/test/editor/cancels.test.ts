import { expect, test } from "vitest";

import { cancelsOf, parseCancels, renamedCancels } from "../../src/editor/model/cancels";

const PROCESS_OF: Record<string, string> = { p3: "N", tc2: "N", t1: "N", p9: "N2" };
const lookup = (id: string) => PROCESS_OF[id];

test("cancels lists nodes of the transition's net, each once, in the order written", () => {
  expect(parseCancels("p3, tc2", "N", lookup)).toEqual(["p3", "tc2"]);
  // A silent transition holds nothing; an importer may list it with its region.
  expect(parseCancels("p3 t1", "N", lookup)).toEqual(["p3", "t1"]);
  expect(parseCancels(" tc2 p3;tc2 ", "N", lookup)).toEqual(["tc2", "p3"]);
  expect(parseCancels("  ", "N", lookup)).toEqual([]);
});

test("every id that cannot be cancelled is named with why, in one message", () => {
  expect(() => parseCancels("p3, nope, p9", "N", lookup)).toThrowError(
    "Cannot cancel: nope is no place or task of this pattern; p9 is in net N2, not in this transition's net N.",
  );
});

test("the list is read from the document and follows a renamed node", () => {
  expect(cancelsOf({ cancels: ["p3", 4, "tc2"] })).toEqual(["p3", "tc2"]);
  expect(cancelsOf({ cancels: "p3" })).toEqual([]);
  expect(renamedCancels({ cancels: ["p3", "tc2"] }, "tc2", "drill")).toEqual(["p3", "drill"]);
  expect(renamedCancels({ cancels: ["p3"] }, "tc2", "drill")).toBeNull();
});
