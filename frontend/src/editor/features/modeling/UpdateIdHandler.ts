/**
 * `element.updateId`: renames a node or an actor. The element id is the
 * document id, so the registry, the document object, the tasks an actor
 * performs, the processes that list the actor and the transitions that cancel
 * the node all follow.
 */

import type Canvas from "diagram-js/lib/core/Canvas";
import type ElementRegistry from "diagram-js/lib/core/ElementRegistry";
import type { CommandContext } from "diagram-js/lib/command/CommandStack";
import type { ElementLike } from "diagram-js/lib/core/Types";

import { isSilent, nodeObject, objectOf, performerOf, type RootObject } from "../../core/elements";
import { renamedCancels } from "../../model/cancels";

export interface UpdateIdContext extends CommandContext {
  element: ElementLike;
  id: string;
  oldId?: string;
}

export default class UpdateIdHandler {
  static $inject = ["elementRegistry", "canvas"];

  constructor(
    private readonly elementRegistry: ElementRegistry,
    private readonly canvas: Canvas,
  ) {}

  execute(context: UpdateIdContext): ElementLike[] {
    context.oldId = context.element.id;
    return this.rename(context.element, context.oldId, context.id);
  }

  revert(context: UpdateIdContext): ElementLike[] {
    return this.rename(context.element, context.id, context.oldId as string);
  }

  private rename(element: ElementLike, from: string, to: string): ElementLike[] {
    const changed: ElementLike[] = [element, ...(element.incoming ?? []), ...(element.outgoing ?? [])];
    this.elementRegistry.updateId(element, to);
    const object = objectOf(element);
    if (object?.kind === "lane") {
      object.data.id = to;
      for (const task of this.elementRegistry.filter((other) => performerOf(other) === from)) {
        nodeObject(task).data.performer = to;
        changed.push(task);
      }
      const root = objectOf(this.canvas.getRootElement()) as RootObject | undefined;
      for (const process of root?.processes ?? []) {
        if (Array.isArray(process.actors)) process.actors = process.actors.map((actor) => (actor === from ? to : actor));
      }
    } else if (object?.kind === "place" || object?.kind === "transition") {
      object.data.id = to;
      for (const transition of this.elementRegistry.filter(isSilent)) {
        const cancels = renamedCancels(nodeObject(transition).data, from, to);
        if (!cancels) continue;
        nodeObject(transition).data.cancels = cancels;
        changed.push(transition);
      }
    }
    return changed;
  }
}
