/**
 * Lanes decide who performs a task: a task dropped or moved into a lane
 * becomes that actor's, and every node takes the net of its lane's actor. Lanes
 * grow to the right with the drawing, and a taller lane pushes the ones below
 * (and what they hold) down. All of it runs inside the command that caused it,
 * so one undo takes it all back.
 */

import CommandInterceptor from "diagram-js/lib/command/CommandInterceptor";
import type Canvas from "diagram-js/lib/core/Canvas";
import type ElementRegistry from "diagram-js/lib/core/ElementRegistry";
import type EventBus from "diagram-js/lib/core/EventBus";
import type { CommandContext } from "diagram-js/lib/command/CommandStack";
import type { Shape } from "diagram-js/lib/model/Types";

import { nextId } from "../../model/ids";
import { centre, isLane, isNode, laneAt, lanesTopDown, laneObject, nodeObject, objectOf, type RootObject } from "../../core/elements";
import type PatternElementFactory from "../../core/PatternElementFactory";
import { SWAPPING_LANES } from "../modeling/MoveLaneHandler";
import type PatternModeling from "../modeling/PatternModeling";

const RIGHT_MARGIN = 160;

export default class LaneBehavior extends CommandInterceptor {
  static $inject = ["eventBus", "elementRegistry", "canvas", "modeling", "elementFactory"];

  constructor(
    eventBus: EventBus,
    private readonly elementRegistry: ElementRegistry,
    private readonly canvas: Canvas,
    private readonly modeling: PatternModeling,
    private readonly elementFactory: PatternElementFactory,
  ) {
    super(eventBus);
    // `true`: the handlers get the command's context, not the event around it.
    this.preExecute("shape.create", (context: CommandContext) => this.placeNew(context.shape, context.position), true);
    this.postExecute(
      "elements.move",
      (context: CommandContext) => {
        // Halfway through a swap a lane's tasks pass over the other lane: they stay its actor's.
        if (!context.hints?.[SWAPPING_LANES]) this.follow(context.shapes as Shape[]);
      },
      true,
    );
    this.postExecute(["shape.create", "elements.move", "elements.create"], () => this.fitWidth(), true);
    this.preExecute(
      "shape.resize",
      (context: CommandContext) => {
        const shape = context.shape as Shape;
        // A person drags only a lane's height; layout and width-fitting pass hints.free.
        if (isLane(shape) && !context.hints?.free) context.newBounds = { x: shape.x, y: shape.y, width: shape.width, height: Math.max(80, context.newBounds.height) };
      },
      true,
    );
    this.postExecute(
      "element.updateData",
      (context: CommandContext) => {
        const process = context.object?.process;
        if (isLane(context.element) && process !== undefined) this.moveNet(context.element, process);
      },
      true,
    );
    this.postExecute(
      "shape.resize",
      (context: CommandContext) => {
        if (!context.hints?.free) this.pushBelow(context.shape, context.oldBounds);
      },
      true,
    );
  }

  lanes(): Shape[] {
    return lanesTopDown(this.elementRegistry.getAll());
  }

  /** The process a node in this lane belongs to: the lane actor's, else the first. */
  processAt(lane: Shape | null): string {
    const root = objectOf(this.canvas.getRootElement()) as RootObject;
    return (lane && laneObject(lane).process) || String(root.processes[0]?.id ?? "N");
  }

  private placeNew(shape: Shape, position: { x: number; y: number; width?: number; height?: number }): void {
    if (!isNode(shape)) return;
    const y = position.height !== undefined ? position.y + position.height / 2 : position.y;
    const lane = laneAt(this.lanes(), y);
    const object = nodeObject(shape);
    object.process = this.processAt(lane);
    if (object.kind !== "transition" || object.silent || !lane) return;
    const renamed = object.data.performer !== lane.id || object.data.id.startsWith("t_new");
    object.data.performer = lane.id;
    if (renamed) {
      // The shape is not on the canvas yet, so its id may still change.
      shape.id = object.data.id = nextId("task", this.elementFactory.isTaken, lane.id);
      this.elementFactory.reserve(shape.id);
    }
  }

  private follow(shapes: Shape[]): void {
    const lanes = this.lanes();
    for (const shape of shapes.filter(isNode)) {
      const lane = laneAt(lanes, centre(shape).y);
      const object = nodeObject(shape);
      const process = this.processAt(lane);
      const performer = object.kind === "transition" && !object.silent && lane ? lane.id : object.data.performer;
      if (process !== object.process || performer !== object.data.performer) {
        this.modeling.updateData(shape, object.kind === "transition" ? { performer } : {}, { process });
      }
    }
  }

  /** A lane given to another net takes the places and transitions drawn in it along. */
  private moveNet(lane: Shape, process: string): void {
    for (const node of this.elementRegistry.filter(isNode) as Shape[]) {
      if (laneAt([lane], centre(node).y) && nodeObject(node).process !== process) this.modeling.updateData(node, {}, { process });
    }
  }

  private fitWidth(): void {
    const root = this.canvas.getRootElement() as Shape;
    const rootObject = objectOf(root) as RootObject;
    const nodes = this.elementRegistry.filter(isNode) as Shape[];
    const needed = Math.max(0, ...nodes.map((node) => node.x + node.width + RIGHT_MARGIN));
    if (needed <= rootObject.width) return;
    const width = Math.ceil(needed / 100) * 100;
    for (const lane of this.lanes()) this.modeling.resizeShape(lane, { x: lane.x, y: lane.y, width, height: lane.height }, undefined, { free: true });
    this.modeling.updateData(root, {}, { width });
  }

  private pushBelow(shape: Shape, old: { y: number; height: number }): void {
    if (!isLane(shape)) return;
    const delta = shape.height - old.height;
    const bottom = old.y + old.height;
    if (delta === 0) return;
    const below = (this.elementRegistry.filter((element) => (isLane(element) || isNode(element)) && element !== shape) as Shape[]).filter(
      (element) => (isLane(element) ? element.y : centre(element).y) >= bottom - 1,
    );
    if (below.length) this.modeling.moveElements(below, { x: 0, y: delta });
  }
}
