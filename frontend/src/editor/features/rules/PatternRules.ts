/**
 * The editing rules: what the format forbids is refused before it is drawn,
 * with the reason (model/rules.ts words them). A higher-priority provider
 * could refine these; the token game shuts editing off above them.
 */

import RuleProvider from "diagram-js/lib/features/rules/RuleProvider";
import type ElementRegistry from "diagram-js/lib/core/ElementRegistry";
import type EventBus from "diagram-js/lib/core/EventBus";
import type Dragging from "diagram-js/lib/features/dragging/Dragging";
import type { Connection, Shape } from "diagram-js/lib/model/Types";

import {
  arcRefusal,
  constraintRefusal,
  LANE_CONNECT_REFUSAL,
  LANE_MOVE_REFUSAL,
  laneRemovalRefusal,
  newTaskRefusal,
  type NodeInfo,
  performerRefusal,
} from "../../model/rules";
import {
  centre,
  type ConstraintObject,
  isArc,
  isConstraint,
  isLane,
  isNode,
  isTask,
  laneAt,
  nodeObject,
  objectOf,
  performerOf,
} from "../../core/elements";
import type LaneBehavior from "../lanes/LaneBehavior";
import type ConnectMode from "../constraints/ConnectMode";
import type Refusals from "./Refusals";

type Box = { x: number; y: number; width?: number; height?: number };

export default class PatternRules extends RuleProvider {
  static $inject = ["eventBus", "elementRegistry", "refusals", "connectMode", "dragging", "laneBehavior"];

  constructor(
    eventBus: EventBus,
    private readonly elementRegistry: ElementRegistry,
    private readonly refusals: Refusals,
    private readonly connectMode: ConnectMode,
    private readonly dragging: Dragging,
    private readonly laneBehavior: LaneBehavior,
  ) {
    super(eventBus);
  }

  init(): void {
    this.addRule("shape.create", (context) => this.canCreate(context.shape, context.target, context.position));
    this.addRule("elements.create", (context) => this.canPaste(context.elements, context.target));
    this.addRule("elements.move", (context) => this.canMove(context.shapes, context.delta, context.target));
    this.addRule("shape.resize", (context) => isLane(context.shape));
    this.addRule("connection.start", (context) => isNode(context.source) || this.refusals.refuse(LANE_CONNECT_REFUSAL));
    this.addRule("connection.create", (context) => this.canConnect(context.source, context.target));
    this.addRule("connection.reconnect", (context) => this.canReconnect(context.connection, context.source, context.target));
    this.addRule("elements.delete", (context) => this.deletable(context.elements));
    this.addRule("element.copy", (context) => !isLane(context.element) && objectOf(context.element)?.kind !== "root");
  }

  private canCreate(shape: Shape, target: Shape | undefined, position: Box): boolean {
    if (!this.isCanvas(target)) return this.refusals.refuse(`Drop it on free space${target ? `, not on ${target.id}` : ""}.`);
    if (!isTask(shape)) return this.allowed();
    const lanes = this.laneBehavior.lanes();
    const lane = laneAt(lanes, position.y);
    const reason = newTaskRefusal(lane?.id ?? null, lanes.length);
    return reason ? this.refusals.refuse(reason) : this.allowed();
  }

  private canPaste(elements: Shape[], target: Shape | undefined): boolean {
    if (!this.isCanvas(target)) return this.refusals.refuse("Paste on free space.");
    if (elements.some(isLane)) return this.refusals.refuse("Lanes cannot be copied: add an actor from the palette.");
    return this.allowed();
  }

  private canMove(shapes: Shape[], delta: { x: number; y: number } | undefined, target: Shape | undefined): boolean | null {
    if (shapes.some(isLane)) return this.refusals.refuse(LANE_MOVE_REFUSAL);
    if (!delta) return true;
    if (target !== undefined && !this.isCanvas(target)) return this.refusals.refuse("Drop it on free space.");
    const lanes = this.laneBehavior.lanes();
    const constraints = this.constraints();
    for (const shape of shapes.filter(isTask)) {
      const lane = laneAt(lanes, centre(shape).y + delta.y);
      if (lane?.id === performerOf(shape)) continue;
      const reason = performerRefusal(shape.id, lane?.id ?? null, constraints, (task) => performerOf(this.elementRegistry.get(task)));
      if (reason) return this.refusals.refuse(reason);
    }
    return this.allowed();
  }

  private canConnect(source: Shape, target: Shape | undefined): false | null | { businessObject: unknown } {
    const start = (this.dragging.context() as { data?: { context?: { start?: unknown } } } | null)?.data?.context?.start;
    // diagram-js also tries the reverse direction; a Petri net arc goes the way it was drawn.
    if (start && source !== start) return false;
    if (!target || objectOf(target)?.kind === "root") return null;
    if (!isNode(source) || !target || !isNode(target)) return this.refusals.refuse(LANE_CONNECT_REFUSAL);
    const kind = this.connectMode.kind;
    const reason =
      kind === "arc"
        ? arcRefusal(this.info(source), this.info(target), this.arcs())
        : constraintRefusal(this.info(source), this.info(target), kind, this.constraints());
    if (reason) return this.refusals.refuse(reason);
    this.allowed();
    if (kind === "arc") return { businessObject: { kind: "arc" } };
    return { businessObject: { kind: "constraint", data: { from: source.id, to: target.id, type: kind } } };
  }

  private canReconnect(connection: Connection, source: Shape, target: Shape): boolean {
    if (!isNode(source) || !isNode(target)) return this.refusals.refuse(LANE_CONNECT_REFUSAL);
    const others = (list: { source: string; target: string }[]) =>
      list.filter((item) => !(item.source === connection.source?.id && item.target === connection.target?.id));
    const reason = isConstraint(connection)
      ? constraintRefusal(this.info(source), this.info(target), (objectOf(connection) as ConstraintObject).data.type, this.constraints().filter((c) => c.from !== connection.source?.id || c.to !== connection.target?.id))
      : arcRefusal(this.info(source), this.info(target), others(this.arcs()));
    return reason ? this.refusals.refuse(reason) : this.allowed();
  }

  /** Everything selected but lanes that still hold tasks; those are refused with the reason. */
  private deletable(elements: Shape[]): Shape[] | false {
    const kept: Shape[] = [];
    let reason: string | null = null;
    for (const element of elements) {
      if (isLane(element)) {
        const tasks = this.elementRegistry.filter((other) => performerOf(other) === element.id && !elements.includes(other as Shape)).map((task) => task.id);
        reason = reason ?? laneRemovalRefusal(element.id, tasks);
        if (tasks.length) continue;
      }
      if (objectOf(element)?.kind !== "root") kept.push(element);
    }
    if (reason) this.refusals.refuse(reason);
    return kept.length ? kept : false;
  }

  private allowed(): true {
    this.refusals.clear();
    return true;
  }

  private isCanvas(target: Shape | undefined): boolean {
    return objectOf(target)?.kind === "root";
  }

  private info(shape: Shape): NodeInfo {
    const object = nodeObject(shape);
    return { id: shape.id, kind: object.kind, performer: object.kind === "transition" && !object.silent ? object.data.performer : undefined, process: object.process };
  }

  private arcs(): { source: string; target: string }[] {
    return (this.elementRegistry.filter(isArc) as Connection[]).map((c) => ({ source: String(c.source?.id), target: String(c.target?.id) }));
  }

  private constraints(): { from: string; to: string; type: string }[] {
    return (this.elementRegistry.filter(isConstraint) as Connection[]).map((c) => ({
      from: String(c.source?.id),
      to: String(c.target?.id),
      type: (objectOf(c) as ConstraintObject).data.type,
    }));
  }
}
