/**
 * Which drawn elements a check issue marks: its nodes and lanes by id, a
 * process by its lanes, and for constraint codes the constraint lines between
 * the two tasks it names. Elements are registered on diagram-js' own registry
 * (jsdom draws no SVG).
 */

import { beforeEach, expect, test } from "vitest";
import Diagram from "diagram-js";
import type Canvas from "diagram-js/lib/core/Canvas";
import type ElementRegistry from "diagram-js/lib/core/ElementRegistry";
import type { ElementLike } from "diagram-js/lib/core/Types";
import type { Connection, Shape } from "diagram-js/lib/model/Types";

import CoreModule from "../../src/editor/core";
import type { RootObject } from "../../src/editor/core/elements";
import type PatternElementFactory from "../../src/editor/core/PatternElementFactory";
import { issueTargets } from "../../src/editor/features/checking/targets";

let registry: ElementRegistry;
let factory: PatternElementFactory;
let root: ElementLike;

function register<T extends Shape | Connection>(element: T): T {
  registry.add(element, document.createElementNS("http://www.w3.org/2000/svg", "g"));
  return element;
}

function task(id: string, performer: string): Shape {
  return register(factory.createShape({ id, businessObject: { kind: "transition", process: "N", silent: false, data: { id, performer } } }));
}

function constraint(source: Shape, target: Shape, type: string): Connection {
  return register(factory.createConnection({ businessObject: { kind: "constraint", data: { from: source.id, to: target.id, type } }, source, target, waypoints: [] }));
}

function ids(code: string, elements: string[]): string[] {
  return issueTargets({ code, message: "", elements }, registry, root).map((element) => element.id);
}

beforeEach(() => {
  const container = document.createElement("div");
  document.body.appendChild(container);
  const diagram = new Diagram({ canvas: { container }, modules: [CoreModule] });
  registry = diagram.get("elementRegistry");
  factory = diagram.get("elementFactory");
  const object: RootObject = { kind: "root", data: {}, processes: [{ id: "N", actors: ["c", "o"] }, { id: "N2", actors: [] }], layoutExtra: {}, width: 800, height: 300 };
  root = diagram.get<Canvas>("canvas").setRootElement(factory.createRoot({ id: "__pattern", businessObject: object }));
  for (const [id, type] of [["c", "cobot"], ["o", "operator"]]) {
    register(factory.createShape({ id, businessObject: { kind: "lane", process: "N", data: { id, type } }, isFrame: true }));
  }
});

test("a constraint issue marks both tasks and every constraint line from the first to the second", () => {
  const [to1, tc2] = [task("to1", "o"), task("tc2", "c")];
  const time = constraint(to1, tc2, "time");
  const space = constraint(to1, tc2, "space");
  constraint(tc2, to1, "func");
  expect(ids("constraint-conflict", ["to1", "tc2"])).toEqual(["to1", "tc2", time.id, space.id]);
});

test("a process issue marks the process' lanes; a process without lanes marks nothing", () => {
  expect(ids("unassigned-workpiece", ["N"])).toEqual(["c", "o"]);
  expect(ids("no-actors", ["N2"])).toEqual([]);
});

test("a condition to rewrite marks the imported transition or place that carries it", () => {
  task("to1", "o");
  register(factory.createShape({ id: "t4", businessObject: { kind: "transition", process: "N", silent: true, data: { id: "t4", rewrite: "JUEL ${x}" } } }));
  register(factory.createShape({ id: "p2", businessObject: { kind: "place", process: "N", data: { id: "p2", rewrite: "loop" } } }));
  expect(ids("to-rewrite", ["t4"])).toEqual(["t4"]);
  expect(ids("to-rewrite", ["p2"])).toEqual(["p2"]);
});

test("an issue on other ids marks them alone, never the root", () => {
  task("to1", "o");
  expect(ids("unsound", ["to1", "__pattern", "gone"])).toEqual(["to1"]);
});
