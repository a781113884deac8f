/**
 * The pattern's command handlers on diagram-js' own command stack: each
 * change is undone by its revert and done again by redo. The elements are
 * registered but not drawn (jsdom has no SVG geometry); what the handlers
 * change is the model.
 */

import { beforeEach, describe, expect, test } from "vitest";
import Diagram from "diagram-js";
import type CommandStack from "diagram-js/lib/command/CommandStack";
import type ElementRegistry from "diagram-js/lib/core/ElementRegistry";
import type Canvas from "diagram-js/lib/core/Canvas";
import type { Shape } from "diagram-js/lib/model/Types";

import CoreModule from "../../src/editor/core";
import type { LaneObject, RootObject, TransitionObject } from "../../src/editor/core/elements";
import type PatternElementFactory from "../../src/editor/core/PatternElementFactory";
import ModelingModule from "../../src/editor/features/modeling";
import type PatternModeling from "../../src/editor/features/modeling/PatternModeling";

let diagram: Diagram;
let modeling: PatternModeling;
let stack: CommandStack;
let registry: ElementRegistry;
let factory: PatternElementFactory;

function register(attrs: Partial<Shape>): Shape {
  const shape = factory.createShape(attrs);
  registry.add(shape, document.createElementNS("http://www.w3.org/2000/svg", "g"));
  return shape;
}

beforeEach(() => {
  const container = document.createElement("div");
  document.body.appendChild(container);
  diagram = new Diagram({ canvas: { container }, modules: [CoreModule, ModelingModule] });
  modeling = diagram.get("modeling");
  stack = diagram.get("commandStack");
  registry = diagram.get("elementRegistry");
  factory = diagram.get("elementFactory");
  const root: RootObject = { kind: "root", data: { name: "A" }, processes: [{ id: "N", actors: ["c", "o"] }], layoutExtra: {}, width: 1000, height: 300 };
  diagram.get<Canvas>("canvas").setRootElement(factory.createRoot({ id: "__pattern", businessObject: root }));
});

describe("element.updateData", () => {
  test("sets and removes keys, and undo and redo take turns", () => {
    const place = register({ businessObject: { kind: "place", process: "N", data: { id: "p1", tokens: 1, note: "keep" } } });
    modeling.updateData(place, { tokens: undefined, label: "buffer" }, { process: "N2" });
    expect(place.businessObject).toEqual({ kind: "place", process: "N2", data: { id: "p1", label: "buffer", note: "keep" } });
    stack.undo();
    expect(place.businessObject).toEqual({ kind: "place", process: "N", data: { id: "p1", tokens: 1, note: "keep" } });
    stack.redo();
    expect(place.businessObject.data).toEqual({ id: "p1", label: "buffer", note: "keep" });
  });

  test("a task's configuration is replaced as a whole and restored as it was", () => {
    const task = register({ businessObject: { kind: "transition", process: "N", silent: false, data: { id: "tc1", performer: "c", task: { step: { number: 2 } } } } });
    const before = (task.businessObject as TransitionObject).data.task;
    modeling.updateData(task, { task: { device: { call: "display.show", args: { text: "hi" } } } });
    stack.undo();
    expect((task.businessObject as TransitionObject).data.task).toBe(before);
  });

  test("a label edit is trimmed and an empty one removes the label", () => {
    const task = register({ businessObject: { kind: "transition", process: "N", silent: false, data: { id: "to1", performer: "o", label: "old" } } });
    modeling.updateLabel(task, "  prepare workpiece ");
    expect((task.businessObject as TransitionObject).data.label).toBe("prepare workpiece");
    modeling.updateLabel(task, "   ");
    expect("label" in (task.businessObject as TransitionObject).data).toBe(false);
    stack.undo();
    stack.undo();
    expect((task.businessObject as TransitionObject).data.label).toBe("old");
  });
});

describe("element.updateId", () => {
  test("renaming an actor renames its lane, its tasks' performer and the net's actor list; undo puts it back", () => {
    const lane = register({ id: "o", businessObject: { kind: "lane", process: "N", data: { id: "o", type: "operator" } }, x: 0, y: 0, width: 1000, height: 100 });
    const task = register({ businessObject: { kind: "transition", process: "N", silent: false, data: { id: "to1", performer: "o" } } });
    modeling.updateId(lane, "o1");
    const root = diagram.get<Canvas>("canvas").getRootElement().businessObject as RootObject;
    expect(registry.get("o1")).toBe(lane);
    expect(registry.get("o")).toBeUndefined();
    expect((lane.businessObject as LaneObject).data.id).toBe("o1");
    expect((task.businessObject as TransitionObject).data.performer).toBe("o1");
    expect(root.processes[0].actors).toEqual(["c", "o1"]);
    stack.undo();
    expect(registry.get("o")).toBe(lane);
    expect((task.businessObject as TransitionObject).data.performer).toBe("o");
    expect(root.processes[0].actors).toEqual(["c", "o"]);
    stack.redo();
    expect(task.id).toBe("to1");
    expect((task.businessObject as TransitionObject).data.performer).toBe("o1");
  });

  test("renaming a node keeps its document id in step", () => {
    const place = register({ businessObject: { kind: "place", process: "N", data: { id: "" } } });
    expect(place.id).toBe("p1");
    modeling.updateId(place, "buffer");
    expect(place.businessObject.data.id).toBe("buffer");
    stack.undo();
    expect([place.id, place.businessObject.data.id]).toEqual(["p1", "p1"]);
  });

  test("renaming a cancelled node renames it in the cancelling transition's list; undo puts it back", () => {
    const task = register({ businessObject: { kind: "transition", process: "N", silent: false, data: { id: "tc1", performer: "c" } } });
    const boundary = register({ businessObject: { kind: "transition", process: "N", silent: true, data: { id: "t9", cancels: ["p4", "tc1"] } } });
    modeling.updateId(task, "drill");
    expect((boundary.businessObject as TransitionObject).data.cancels).toEqual(["p4", "drill"]);
    stack.undo();
    expect((boundary.businessObject as TransitionObject).data.cancels).toEqual(["p4", "tc1"]);
  });
});

describe("new elements", () => {
  test("get ids in the thesis' style, never one in use", () => {
    register({ id: "c", businessObject: { kind: "lane", process: "N", data: { id: "c", type: "cobot" } }, x: 0, y: 0, width: 10, height: 10 });
    const task = factory.createShape({ businessObject: { kind: "transition", process: "N", silent: false, data: { id: "", performer: "c" } } });
    const next = factory.createShape({ businessObject: { kind: "transition", process: "N", silent: false, data: { id: "", performer: "c" } } });
    const silent = factory.createShape({ businessObject: { kind: "transition", process: "N", silent: true, data: { id: "" } } });
    expect([task.id, next.id, silent.id]).toEqual(["tc1", "tc2", "t1"]);
    expect([task.width, task.height, silent.width]).toEqual([100, 60, 20]);
    expect(factory.isTaken("N")).toBe(true);
  });
});

describe("constraint.reverse", () => {
  test("swaps the constraint's tasks and one undo swaps them back", () => {
    const operator = register({ businessObject: { kind: "transition", process: "N", silent: false, data: { id: "to1", performer: "o", label: "Press the button" } } });
    const cobot = register({ businessObject: { kind: "transition", process: "N", silent: false, data: { id: "tc1", performer: "c", label: "Move part" } } });
    const constraint = factory.createConnection({
      id: "constraint-1",
      source: operator,
      target: cobot,
      waypoints: [{ x: 0, y: 0 }, { x: 10, y: 20 }],
      businessObject: { kind: "constraint", data: { from: "to1", to: "tc1", type: "time" } },
    });
    registry.add(constraint, document.createElementNS("http://www.w3.org/2000/svg", "g"));

    modeling.reverseConstraint(constraint);
    expect([constraint.source?.id, constraint.target?.id]).toEqual(["tc1", "to1"]);
    expect(constraint.waypoints).toEqual([{ x: 10, y: 20 }, { x: 0, y: 0 }]);
    expect(cobot.outgoing).toEqual([constraint]);
    expect(operator.incoming).toEqual([constraint]);
    expect(operator.outgoing).toEqual([]);

    stack.undo();
    expect([constraint.source?.id, constraint.target?.id]).toEqual(["to1", "tc1"]);
    expect(operator.outgoing).toEqual([constraint]);
    expect(cobot.incoming).toEqual([constraint]);
  });
});
