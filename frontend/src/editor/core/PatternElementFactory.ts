/**
 * Makes diagram elements for pattern objects: the right size for each kind and
 * the document id as the element id (p3, tc2, the actor's id for a lane), so
 * the server's answers, which name document ids, find their elements.
 */

import ElementFactory from "diagram-js/lib/core/ElementFactory";
import type ElementRegistry from "diagram-js/lib/core/ElementRegistry";
import type Canvas from "diagram-js/lib/core/Canvas";

import { nextId } from "../model/ids";
import { type Injector, objectOf, sizeOf, type NodeObject, type RootObject } from "./elements";

export default class PatternElementFactory extends ElementFactory {
  static $inject = ["elementRegistry", "injector"];

  /** Ids handed out but perhaps not on the canvas yet (a paste makes all its elements first). */
  private readonly reserved = new Set<string>();
  private connectionCount = 0;

  constructor(
    private readonly elementRegistry: ElementRegistry,
    private readonly injector: Injector,
  ) {
    super();
  }

  // The base class types create() per element type; one implementation serves them all.
  // eslint-disable-next-line @typescript-eslint/no-explicit-any
  create(type: any, attrs: any = {}): any {
    const filled = { ...attrs };
    const object = objectOf(filled);
    if (type === "shape" && (object?.kind === "place" || object?.kind === "transition")) {
      Object.assign(filled, sizeOf(object));
      if (!filled.id) filled.id = this.nodeId(object);
      object.data.id = filled.id;
    }
    if (type === "connection" && !filled.id) {
      this.connectionCount += 1;
      filled.id = `${object?.kind ?? "connection"}:${this.connectionCount}`;
    }
    return super.create(type, filled);
  }

  /** Whether an id is used anywhere in the pattern: elements, processes, or reserved a moment ago. */
  isTaken = (id: string): boolean => {
    if (this.reserved.has(id) || this.elementRegistry.get(id)) return true;
    const canvas = this.injector.get<Canvas>("canvas");
    const root = objectOf(canvas.getRootElement()) as RootObject | undefined;
    return (root?.processes ?? []).some((process) => process.id === id);
  };

  /** A fresh id in the thesis' style; a task's depends on its actor, so one without an actor yet gets a placeholder. */
  nodeId(object: NodeObject): string {
    let id: string;
    if (object.kind === "place") id = nextId("place", this.isTaken);
    else if (object.silent) id = nextId("silent", this.isTaken);
    else if (object.data.performer) id = nextId("task", this.isTaken, object.data.performer);
    else id = nextId("task", this.isTaken, "_new");
    this.reserved.add(id);
    return id;
  }

  reserve(id: string): void {
    this.reserved.add(id);
  }

  /** Forgets reservations (after an import: the registry is the truth again). */
  clearReservations(): void {
    this.reserved.clear();
  }
}
