/**
 * The reason for the last refused edit. Rules call refuse(); the hint shows
 * the reason while the refused drop, connection or key press is still under
 * the engineer's hand.
 */

import type EventBus from "diagram-js/lib/core/EventBus";

export default class Refusals {
  static $inject = ["eventBus"];

  reason: string | null = null;

  constructor(private readonly eventBus: EventBus) {}

  /** Records why and returns false, so a rule can `return refusals.refuse(...)`. */
  refuse(reason: string): false {
    if (reason !== this.reason) {
      this.reason = reason;
      this.eventBus.fire("refusal.changed", { reason });
    }
    return false;
  }

  clear(): void {
    if (this.reason === null) return;
    this.reason = null;
    this.eventBus.fire("refusal.changed", { reason: null });
  }
}
