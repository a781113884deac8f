import { expect, test } from "vitest";

import { idProblem, nextId } from "../../src/editor/model/ids";

const taken = (...ids: string[]) => (id: string) => ids.includes(id);

test("new ids follow the thesis: p<n>, t<n>, t<actor><n>, actors c/o then c2/o2", () => {
  expect(nextId("place", taken("p1", "p2"))).toBe("p3");
  expect(nextId("silent", taken("t1"))).toBe("t2");
  expect(nextId("task", taken("tc1"), "c")).toBe("tc2");
  expect(nextId("task", taken(), "o1")).toBe("to11");
  expect(nextId("actor", taken(), "cobot")).toBe("c");
  expect(nextId("actor", taken("o"), "operator")).toBe("o2");
  expect(nextId("process", taken("N", "N2"))).toBe("N3");
});

test("an id an engineer types must be plain and free", () => {
  expect(idProblem("tc9", taken("tc1"))).toBeNull();
  expect(idProblem("tc1", taken("tc1"))).toBe("The id tc1 is already used in this pattern.");
  expect(idProblem("", taken())).toBe("An id cannot be empty.");
  expect(idProblem("a b", taken())).toMatch(/^"a b" is not a plain id/);
});
