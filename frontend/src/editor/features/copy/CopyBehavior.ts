/**
 * Copy and paste: a pasted node gets its own copy of the document object and a
 * fresh id (its label, tokens and task configuration come along); a pasted
 * constraint keeps its kind.
 */

import type EventBus from "diagram-js/lib/core/EventBus";

import { objectOf } from "../../core/elements";

interface Descriptor {
  businessObject?: unknown;
  id?: string;
}

export default class CopyBehavior {
  static $inject = ["eventBus"];

  constructor(eventBus: EventBus) {
    eventBus.on("copyPaste.copyElement", 500, (context: { descriptor: Descriptor; element: unknown }) => {
      const object = objectOf(context.element as Descriptor);
      if (object) context.descriptor.businessObject = structuredClone(object);
    });
    eventBus.on("copyPaste.pasteElement", (context: { descriptor: Descriptor }) => {
      // Each paste needs fresh objects: the clipboard's copy stays for the next paste.
      const object = structuredClone(context.descriptor.businessObject) as { data?: { id?: string } } | undefined;
      if (object?.data && "id" in object.data) object.data.id = "";
      context.descriptor.businessObject = object;
    });
  }
}
