/**
 * diagram-js modeling plus the pattern's own commands; every change goes
 * through the command stack, so each can be undone and redone.
 */

import Modeling from "diagram-js/lib/features/modeling/Modeling";
import type CommandStack from "diagram-js/lib/command/CommandStack";
import type EventBus from "diagram-js/lib/core/EventBus";
import type { ElementLike } from "diagram-js/lib/core/Types";
import type { Connection, Shape } from "diagram-js/lib/model/Types";

import type { ActorType, Extra } from "../../model/document";
import type PatternElementFactory from "../../core/PatternElementFactory";
import AddLaneHandler, { type AddLaneContext } from "./AddLaneHandler";
import MoveLaneHandler, { type MoveLaneContext } from "./MoveLaneHandler";
import ReverseConstraintHandler, { type ReverseConstraintContext } from "./ReverseConstraintHandler";
import UpdateDataHandler from "./UpdateDataHandler";
import UpdateIdHandler from "./UpdateIdHandler";

export default class PatternModeling extends Modeling {
  static $inject = ["eventBus", "elementFactory", "commandStack"];

  private readonly commands: CommandStack;

  constructor(eventBus: EventBus, elementFactory: PatternElementFactory, commandStack: CommandStack) {
    super(eventBus, elementFactory, commandStack);
    this.commands = commandStack;
  }

  // eslint-disable-next-line @typescript-eslint/no-explicit-any
  getHandlers(): any {
    const handlers = super.getHandlers() as unknown as Record<string, unknown>;
    return {
      ...handlers,
      "element.updateData": UpdateDataHandler,
      "element.updateId": UpdateIdHandler,
      "lane.add": AddLaneHandler,
      "lane.move": MoveLaneHandler,
      "constraint.reverse": ReverseConstraintHandler,
    };
  }

  /** Sets keys of the element's document object (undefined removes one) and of its pattern object. */
  updateData(element: ElementLike, data: Extra, object: Extra = {}): void {
    this.commands.execute("element.updateData", { element, data, object });
  }

  updateLabel(element: ElementLike, label: string): void {
    this.updateData(element, { label: label.trim() || undefined });
  }

  updateId(element: ElementLike, id: string): void {
    this.commands.execute("element.updateId", { element, id });
  }

  /** Swaps the lane with the one above (-1) or below (1) it; nothing at either end. */
  moveLane(lane: Shape, by: -1 | 1): void {
    const context: MoveLaneContext = { lane, by };
    this.commands.execute("lane.move", context);
  }

  /** Swaps a constraint's source and target task, as one undoable step. */
  reverseConstraint(connection: Connection): void {
    const context: ReverseConstraintContext = { connection };
    this.commands.execute("constraint.reverse", context);
  }

  addLane(type: ActorType, id?: string): Shape {
    const context: AddLaneContext = { type, id };
    this.commands.execute("lane.add", context);
    return context.shape as Shape;
  }
}
