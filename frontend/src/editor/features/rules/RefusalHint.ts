/** Shows why an edit was refused, where the engineer is looking, while it matters. */

import type Canvas from "diagram-js/lib/core/Canvas";
import type EventBus from "diagram-js/lib/core/EventBus";

const SHOWN_FOR_MS = 6000;

export default class RefusalHint {
  static $inject = ["eventBus", "canvas"];

  private readonly box: HTMLElement;
  private timer: ReturnType<typeof setTimeout> | undefined;

  constructor(eventBus: EventBus, canvas: Canvas) {
    this.box = document.createElement("div");
    this.box.className = "hrc-refusal";
    this.box.setAttribute("role", "status");
    this.box.hidden = true;
    canvas.getContainer().appendChild(this.box);
    eventBus.on("refusal.changed", (event: { reason: string | null }) => this.show(event.reason));
  }

  show(reason: string | null): void {
    clearTimeout(this.timer);
    this.box.hidden = reason === null;
    this.box.textContent = reason ?? "";
    if (reason !== null) this.timer = setTimeout(() => (this.box.hidden = true), SHOWN_FOR_MS);
  }
}
