/**
 * `element.updateData`: sets keys of an element's document object (`data`) and
 * of the pattern object itself (`object`, e.g. a node's process). A value of
 * undefined removes the key. Revert puts every old value back, so undo and
 * redo come from the command stack.
 */

import type ElementRegistry from "diagram-js/lib/core/ElementRegistry";
import type { CommandContext } from "diagram-js/lib/command/CommandStack";
import type { ElementLike } from "diagram-js/lib/core/Types";

import type { Extra } from "../../model/document";
import { objectOf, performerOf } from "../../core/elements";

const ABSENT = Symbol("absent");

// A key's value before the update, or ABSENT where the key was not there.
type Old = Record<string, unknown>;

export interface UpdateDataContext extends CommandContext {
  element: ElementLike;
  data?: Extra;
  object?: Extra;
  old?: { data: Old; object: Old };
}

export default class UpdateDataHandler {
  static $inject = ["elementRegistry"];

  constructor(private readonly elementRegistry: ElementRegistry) {}

  execute(context: UpdateDataContext): ElementLike[] {
    const object = objectOf(context.element) as unknown as Extra & { data?: Extra };
    context.old = {
      data: object.data ? apply(object.data, context.data ?? {}) : {},
      object: apply(object, context.object ?? {}),
    };
    return this.changed(context.element);
  }

  revert(context: UpdateDataContext): ElementLike[] {
    const object = objectOf(context.element) as unknown as Extra & { data?: Extra };
    const old = context.old as { data: Old; object: Old };
    apply(object, old.object);
    if (object.data) apply(object.data, old.data);
    return this.changed(context.element);
  }

  /** The element, and for a lane the tasks of its actor, which are drawn in its colours. */
  private changed(element: ElementLike): ElementLike[] {
    if (objectOf(element)?.kind !== "lane") return [element];
    return [element, ...this.elementRegistry.filter((other) => performerOf(other) === element.id)];
  }
}

/** Sets the changes on target and returns what the changed keys held before. */
function apply(target: Extra, changes: Old): Old {
  const old: Old = {};
  for (const [key, value] of Object.entries(changes)) {
    old[key] = key in target ? target[key] : ABSENT;
    if (value === undefined || value === ABSENT) delete target[key];
    else target[key] = value;
  }
  return old;
}
