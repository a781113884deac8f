import { expect, test } from "vitest";

import { jsonProblem } from "../../src/editor/model/json";

test.each([
  ['{"a": 1}', null],
  ["[1, -2.5e3, true, null, \"\\u00e9\\n\"]", null],
  ["{\n  \"a\": 01\n}", { line: 2, column: 9, found: '"1"' }],
  ['{"a" 1}', { line: 1, column: 6, found: '"1"' }],
  ["[1, 2,]", { line: 1, column: 7, found: '"]"' }],
  ["{\"a\": tru}", { line: 1, column: 7, found: '"t"' }],
  ["[\"open", { line: 1, column: 7, found: "the end of the file" }],
  ["{} {}", { line: 1, column: 4, found: '"{"' }],
])("%j", (text, problem) => {
  expect(jsonProblem(text)).toEqual(problem);
  expect(problem === null).toBe((() => {
    try {
      JSON.parse(text);
      return true;
    } catch {
      return false;
    }
  })());
});
