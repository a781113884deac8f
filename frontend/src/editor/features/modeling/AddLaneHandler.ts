/**
 * `lane.add`: a new actor as a lane under the others, as wide as the drawing.
 * Its process is the one net when there is one; in a coexistence pattern
 * (several nets, one actor each) a new actor gets a net of its own.
 */

import type Canvas from "diagram-js/lib/core/Canvas";
import type ElementRegistry from "diagram-js/lib/core/ElementRegistry";
import type { CommandContext } from "diagram-js/lib/command/CommandStack";
import type { Shape } from "diagram-js/lib/model/Types";

import { type ActorType, DEFAULT_WORKPIECE, type Extra } from "../../model/document";
import { nextId } from "../../model/ids";
import { LANE_HEIGHT } from "../../model/snapshot";
import { isLane, type LaneObject, objectOf, type RootObject } from "../../core/elements";
import type PatternElementFactory from "../../core/PatternElementFactory";
import type PatternModeling from "./PatternModeling";

export interface AddLaneContext extends CommandContext {
  type: ActorType;
  id?: string;
  shape?: Shape;
}

export default class AddLaneHandler {
  static $inject = ["canvas", "elementRegistry", "elementFactory", "modeling"];

  constructor(
    private readonly canvas: Canvas,
    private readonly elementRegistry: ElementRegistry,
    private readonly elementFactory: PatternElementFactory,
    private readonly modeling: PatternModeling,
  ) {}

  preExecute(context: AddLaneContext): void {
    const root = this.canvas.getRootElement() as Shape;
    const rootObject = objectOf(root) as RootObject;
    const lanes = this.elementRegistry.filter(isLane) as Shape[];
    const id = context.id ?? nextId("actor", this.elementFactory.isTaken, context.type);
    const object: LaneObject = { kind: "lane", process: this.processFor(root, lanes), data: { id, type: context.type } };
    const y = Math.max(0, ...lanes.map((lane) => lane.y + lane.height));
    const width = Math.max(rootObject.width, ...lanes.map((lane) => lane.width));
    const shape = this.elementFactory.createShape({ id, businessObject: object, width, height: LANE_HEIGHT, isFrame: true });
    const bounds = { x: 0, y, width, height: LANE_HEIGHT };
    context.shape = this.modeling.createShape(shape, bounds, root, 0);
  }

  private processFor(root: Shape, lanes: Shape[]): string | null {
    const processes = (objectOf(root) as RootObject).processes;
    if (processes.length === 0) return null;
    const actorsOf = (process: Extra) => lanes.filter((lane) => (objectOf(lane) as LaneObject).process === process.id).length;
    const coexistence = processes.length > 1 && processes.every((process) => actorsOf(process) === 1);
    if (!coexistence) return String(processes[0].id);
    const id = nextId("process", this.elementFactory.isTaken);
    this.modeling.updateData(root, {}, { processes: [...processes, { id, workpiece: DEFAULT_WORKPIECE, actors: [] }] });
    return id;
  }
}
