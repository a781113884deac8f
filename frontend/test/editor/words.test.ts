import { describe, expect, test } from "vitest";

import { listOfNames, quotedName } from "../../src/editor/model/words";

describe("naming elements for a button", () => {
  const labels: Record<string, string | undefined> = { p1: undefined, tc1: "Pick insert", tc2: "Place insert", to1: "Prepare", to2: "Check" };
  const name = (id: string) => quotedName(id, labels[id]);

  test("names each element once, by its label, by its id only where it has none", () => {
    expect(listOfNames(["p1", "p2", "p1", "p2"], name)).toBe("p1 and p2");
    expect(listOfNames(["tc1", "p1", "tc1"], name)).toBe("“Pick insert” and p1");
  });

  test("shortens a long list", () => {
    expect(listOfNames(["tc1", "tc2", "to1", "to2", "p1"], name)).toBe("“Pick insert”, “Place insert”, “Prepare” and 2 more");
  });

  test("a blank label counts as none", () => {
    expect(quotedName("t1", "  ")).toBe("t1");
  });
});
