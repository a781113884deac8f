/**
 * What the next connection drawn will be: an arc, or a constraint of one
 * kind. The context pad and palette set it before a connect starts; it falls
 * back to an arc when the connect ends.
 */

import type EventBus from "diagram-js/lib/core/EventBus";

import type { ConstraintType } from "../../model/document";

export type ConnectionKind = "arc" | ConstraintType;

export default class ConnectMode {
  static $inject = ["eventBus"];

  kind: ConnectionKind = "arc";

  constructor(eventBus: EventBus) {
    eventBus.on("connect.cleanup", () => {
      this.kind = "arc";
    });
  }
}
