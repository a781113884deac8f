import { expect, test } from "vitest";

import { fieldsOfForm, formOfFields, parsePose, parsePoses, parseWhole, taskKind, withKind } from "../../src/editor/model/taskconfig";

test("a pose is six numbers or an expression", () => {
  expect(parsePose("0.1, 0.2 0.05;0 0 0")).toEqual([0.1, 0.2, 0.05, 0, 0, 0]);
  expect(parsePose(" =data.pick_pose ")).toBe("=data.pick_pose");
  expect(() => parsePose("1, 2, 3")).toThrowError("A pose is 6 numbers (x, y, z, rx, ry, rz) or an expression starting with =; got 3 values.");
  expect(() => parsePose("1, 2, 3, 4, 5, x")).toThrowError('"x" is not a number.');
});

test("a step takes at most two poses, each checked with its line", () => {
  expect(parsePoses("0 0 0 0 0 0\n=data.place_pose\n")).toEqual([[0, 0, 0, 0, 0, 0], "=data.place_pose"]);
  expect(() => parsePoses("1\n2\n3")).toThrowError("A step takes at most 2 poses.");
  expect(() => parsePoses("0 0 0 0 0 0\n1 2")).toThrowError(/^Pose 2: A pose is 6 numbers/);
});

test("step numbers and workspaces are whole numbers or expressions", () => {
  expect(parseWhole("3", "number")).toBe(3);
  expect(parseWhole("=data.step", "number")).toBe("=data.step");
  expect(() => parseWhole("-1", "workspace")).toThrowError("The step's workspace must be a whole number ≥ 0 or an expression starting with =.");
});

test("a cobot task runs a step unless it has a device call; an operator's is a form", () => {
  expect(taskKind({}, "operator")).toBe("operator");
  expect(taskKind({}, "cobot")).toBe("step");
  expect(taskKind({ device: { call: "display.show" } }, "cobot")).toBe("device");
  expect(withKind({ instructions: "x", step: { number: 2 } }, "device")).toEqual({ instructions: "x", device: { call: "part-detection.scan", args: {} } });
  expect(withKind({ device: { call: "display.show" } }, "step")).toEqual({ step: { number: 1, workspace: 0, poses: [] } });
});

test("form fields become a JSON Schema object and back, keeping what the panel does not edit", () => {
  const previous = { type: "object", properties: { count: { type: "integer", minimum: 0 } }, additionalProperties: false };
  const form = formOfFields(
    [
      { name: "count", type: "integer", title: "Parts counted", required: true },
      { name: "ok", type: "boolean", title: "", required: false },
    ],
    previous,
  );
  expect(form).toEqual({
    type: "object",
    additionalProperties: false,
    properties: { count: { type: "integer", minimum: 0, title: "Parts counted" }, ok: { type: "boolean" } },
    required: ["count"],
  });
  expect(fieldsOfForm(form)).toEqual([
    { name: "count", type: "integer", title: "Parts counted", required: true },
    { name: "ok", type: "boolean", title: "", required: false },
  ]);
  expect(formOfFields([])).toBeUndefined();
  expect(() => formOfFields([{ name: "a b", type: "string", title: "", required: false }])).toThrowError('"a b" is not a field name: use letters, digits and _.');
});
