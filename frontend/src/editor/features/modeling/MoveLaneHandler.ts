/**
 * `lane.move`: an actor's lane changes places with the one above or below it,
 * taking what is drawn in it along; who performs each task stays as it was.
 * Both moves run inside this command, so one undo takes the swap back.
 */

import type ElementRegistry from "diagram-js/lib/core/ElementRegistry";
import type { CommandContext } from "diagram-js/lib/command/CommandStack";
import type { Shape } from "diagram-js/lib/model/Types";

import { centre, isNode, laneAt, lanesTopDown } from "../../core/elements";
import type PatternModeling from "./PatternModeling";

export interface MoveLaneContext extends CommandContext {
  lane: Shape;
  by: -1 | 1; // up, down
}

/** The hint that tells the lanes' behaviour not to re-assign what a swap moves through another lane. */
export const SWAPPING_LANES = "swappingLanes";

export default class MoveLaneHandler {
  static $inject = ["elementRegistry", "modeling"];

  constructor(
    private readonly elementRegistry: ElementRegistry,
    private readonly modeling: PatternModeling,
  ) {}

  preExecute(context: MoveLaneContext): void {
    const lanes = lanesTopDown(this.elementRegistry.getAll());
    const index = lanes.indexOf(context.lane);
    const other = lanes[index + context.by];
    if (index < 0 || !other) return; // the first lane goes no higher, the last no lower
    const [upper, lower] = context.by < 0 ? [other, context.lane] : [context.lane, other];
    const nodes = this.elementRegistry.filter(isNode) as Shape[];
    const inside = (lane: Shape) => nodes.filter((node) => laneAt([lane], centre(node).y));
    const [upperNodes, lowerNodes] = [inside(upper), inside(lower)];
    const hints = { [SWAPPING_LANES]: true };
    this.modeling.moveElements([upper, ...upperNodes], { x: 0, y: lower.height }, undefined, hints);
    this.modeling.moveElements([lower, ...lowerNodes], { x: 0, y: -upper.height }, undefined, hints);
  }
}
