/**
 * Puts a snapshot of the document on the canvas and reads it back. Importing
 * is not a command: it starts a new history (the command stack is cleared).
 */

import type Canvas from "diagram-js/lib/core/Canvas";
import type ElementRegistry from "diagram-js/lib/core/ElementRegistry";
import type EventBus from "diagram-js/lib/core/EventBus";
import type CommandStack from "diagram-js/lib/command/CommandStack";
import type { Connection, Element, Shape } from "diagram-js/lib/model/Types";
import { getMid } from "diagram-js/lib/layout/LayoutUtil";

import type { PatternDocument } from "../model/document";
import { type Snapshot, toDocument, toSnapshot } from "../model/snapshot";
import {
  type ConstraintObject,
  isNode,
  laneObject,
  lanesTopDown,
  nodeObject,
  objectOf,
  type PatternObject,
  type RootObject,
} from "./elements";
import type PatternElementFactory from "./PatternElementFactory";

export const ROOT_ID = "__pattern";

interface ConnectionDocking {
  getCroppedWaypoints(connection: Connection, source: Shape, target: Shape): { x: number; y: number }[];
}

export default class PatternImporter {
  static $inject = ["canvas", "elementFactory", "elementRegistry", "eventBus", "commandStack", "connectionDocking"];

  constructor(
    private readonly canvas: Canvas,
    private readonly elementFactory: PatternElementFactory,
    private readonly elementRegistry: ElementRegistry,
    private readonly eventBus: EventBus,
    private readonly commandStack: CommandStack,
    private readonly connectionDocking: ConnectionDocking,
  ) {}

  /**
   * Draws a document that has a layout (model/snapshot.hasLayout). Returns
   * what could not be drawn (an arc or constraint naming an unknown node), in words.
   */
  importDocument(document: PatternDocument): string[] {
    return this.importSnapshot(toSnapshot(document));
  }

  importSnapshot(snapshot: Snapshot): string[] {
    this.eventBus.fire("import.start", {});
    // What Diagram.clear() does: canvas, overlays, selection and command stack forget everything.
    this.eventBus.fire("diagram.clear", {});
    this.elementFactory.clearReservations();
    const rootObject: RootObject = {
      kind: "root",
      data: snapshot.root,
      processes: snapshot.processes,
      layoutExtra: snapshot.layoutExtra,
      width: snapshot.width,
      height: snapshot.height,
    };
    const root = this.canvas.setRootElement(this.elementFactory.createRoot({ id: ROOT_ID, businessObject: rootObject })) as Element;
    for (const lane of snapshot.lanes) {
      this.add({ id: lane.actor.id, businessObject: { kind: "lane", process: lane.process, data: lane.actor }, x: 0, y: lane.y, width: snapshot.width, height: lane.height, isFrame: true }, root);
    }
    for (const node of snapshot.nodes) {
      const object: PatternObject =
        node.kind === "place"
          ? { kind: "place", process: node.process, data: node.data }
          : { kind: "transition", process: node.process, silent: !node.data.performer, data: node.data };
      const shape = this.elementFactory.createShape({ id: node.data.id, businessObject: object });
      shape.x = Math.round(node.x - shape.width / 2);
      shape.y = Math.round(node.y - shape.height / 2);
      this.canvas.addShape(shape, root);
    }
    const dropped: string[] = [];
    for (const arc of snapshot.arcs) {
      if (!this.connect(arc.source, arc.target, { kind: "arc" })) dropped.push(`the arc ${arc.source} → ${arc.target}`);
    }
    for (const constraint of snapshot.constraints) {
      const object: ConstraintObject = { kind: "constraint", data: constraint };
      if (!this.connect(constraint.from, constraint.to, object)) {
        dropped.push(`the ${constraint.type} constraint ${constraint.from} → ${constraint.to}`);
      }
    }
    this.commandStack.clear();
    this.eventBus.fire("import.done", { dropped });
    return dropped;
  }

  private add(attrs: Partial<Shape>, root: Element): Shape {
    const shape = this.elementFactory.createShape(attrs);
    this.canvas.addShape(shape, root);
    return shape;
  }

  private connect(sourceId: string, targetId: string, object: PatternObject): boolean {
    const source = this.elementRegistry.get(sourceId) as Shape | undefined;
    const target = this.elementRegistry.get(targetId) as Shape | undefined;
    if (!source || !target || !isNode(source) || !isNode(target)) return false;
    const connection = this.elementFactory.createConnection({ businessObject: object, source, target, waypoints: [getMid(source), getMid(target)] });
    connection.waypoints = this.connectionDocking.getCroppedWaypoints(connection, source, target);
    this.canvas.addConnection(connection, this.canvas.getRootElement() as Element);
    return true;
  }

  /** The canvas as a snapshot: lanes top to bottom, nodes and connections in the order they were made. */
  snapshot(): Snapshot {
    const root = objectOf(this.canvas.getRootElement()) as RootObject;
    const elements = this.elementRegistry.getAll();
    const lanes = lanesTopDown(elements);
    const nodes = elements.filter(isNode) as Shape[];
    const connections = elements.filter((element) => "waypoints" in element) as Connection[];
    const width = Math.max(root.width, ...lanes.map((lane) => lane.width));
    return {
      root: root.data,
      processes: root.processes,
      lanes: lanes.map((lane) => ({ actor: { ...laneObject(lane).data, id: lane.id }, process: laneObject(lane).process, y: lane.y, height: lane.height })),
      nodes: nodes.map((shape) => {
        const object = nodeObject(shape);
        return { kind: object.kind, process: object.process, data: { ...object.data, id: shape.id }, x: shape.x + shape.width / 2, y: shape.y + shape.height / 2 };
      }),
      arcs: connections.filter((c) => objectOf(c)?.kind === "arc").map((c) => ({ source: (c.source as Element).id, target: (c.target as Element).id })),
      constraints: connections
        .filter((c) => objectOf(c)?.kind === "constraint")
        .map((c) => ({ ...(objectOf(c) as ConstraintObject).data, from: (c.source as Element).id, to: (c.target as Element).id })),
      layoutExtra: root.layoutExtra,
      width,
      height: Math.max(root.height, ...lanes.map((lane) => lane.y + lane.height), ...nodes.map((node) => node.y + node.height + 20)),
    };
  }

  /** The hrc-pattern/1 document of what is on the canvas, with its layout. */
  document(): PatternDocument {
    return toDocument(this.snapshot());
  }
}
