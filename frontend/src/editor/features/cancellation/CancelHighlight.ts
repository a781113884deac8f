/**
 * What a cancelling transition empties stands out while the transition is
 * under the mouse or selected: each place and task its `cancels` key lists.
 */

import type Canvas from "diagram-js/lib/core/Canvas";
import type ElementRegistry from "diagram-js/lib/core/ElementRegistry";
import type EventBus from "diagram-js/lib/core/EventBus";
import type { Element } from "diagram-js/lib/model/Types";

import { isSilent, nodeObject } from "../../core/elements";
import { cancelsOf } from "../../model/cancels";

const MARKER = "hrc-cancelled";

export default class CancelHighlight {
  static $inject = ["eventBus", "canvas", "elementRegistry"];

  private hovered: Element | null = null;
  private selected: Element | null = null;
  private lit: string[] = [];

  constructor(
    eventBus: EventBus,
    private readonly canvas: Canvas,
    private readonly elementRegistry: ElementRegistry,
  ) {
    eventBus.on("element.hover", (event: { element: Element }) => {
      this.hovered = event.element;
      this.light();
    });
    eventBus.on("element.out", (event: { element: Element }) => {
      if (event.element !== this.hovered) return;
      this.hovered = null;
      this.light();
    });
    eventBus.on("selection.changed", (event: { newSelection: Element[] }) => {
      this.selected = event.newSelection.length === 1 ? event.newSelection[0] : null;
      this.light();
    });
    // An edit of the key, or an id renamed or deleted, changes what is lit.
    eventBus.on("commandStack.changed", () => this.light());
    eventBus.on("diagram.clear", () => {
      this.hovered = this.selected = null;
      this.lit = [];
    });
  }

  private light(): void {
    for (const id of this.lit) if (this.elementRegistry.get(id)) this.canvas.removeMarker(id, MARKER);
    const ids = [this.hovered, this.selected].flatMap((element) => (isSilent(element) ? cancelsOf(nodeObject(element).data) : []));
    this.lit = [...new Set(ids)].filter((id) => this.elementRegistry.get(id));
    for (const id of this.lit) this.canvas.addMarker(id, MARKER);
  }
}
