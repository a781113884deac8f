/**
 * A constraint under the mouse stands out, and so do the two tasks it joins;
 * the legend says what each kind of line means.
 */

import type Canvas from "diagram-js/lib/core/Canvas";
import type EventBus from "diagram-js/lib/core/EventBus";
import type { Connection } from "diagram-js/lib/model/Types";

import { isConstraint } from "../../core/elements";
import { CONSTRAINT_STYLE } from "../../core/PatternRenderer";
import { ICONS } from "../palette/icons";

export default class ConstraintHighlight {
  static $inject = ["eventBus", "canvas"];

  private lit: Connection | null = null;

  constructor(
    eventBus: EventBus,
    private readonly canvas: Canvas,
  ) {
    eventBus.on("element.hover", (event: { element: Connection }) => {
      if (isConstraint(event.element)) this.light(event.element);
    });
    eventBus.on("element.out", (event: { element: Connection }) => {
      if (event.element === this.lit) this.light(null);
    });
    eventBus.on("diagram.clear", () => (this.lit = null));
    canvas.getContainer().appendChild(legend());
  }

  light(connection: Connection | null): void {
    const marks: [Connection | null, boolean][] = [
      [this.lit, false],
      [connection, true],
    ];
    for (const [element, on] of marks) {
      if (!element) continue;
      for (const [target, marker] of [
        [element, "hrc-lit"],
        [element.source, "hrc-lit-end"],
        [element.target, "hrc-lit-end"],
      ] as const) {
        if (!target) continue;
        if (on) this.canvas.addMarker(target.id, marker);
        else this.canvas.removeMarker(target.id, marker);
      }
    }
    this.lit = connection;
  }
}

function legend(): HTMLElement {
  const box = document.createElement("aside");
  box.className = "hrc-legend";
  box.setAttribute("aria-label", "Constraint legend");
  box.innerHTML =
    "<strong>Constraints</strong>" +
    Object.entries(CONSTRAINT_STYLE)
      .map(([type, style]) => `<div class="hrc-legend-row" data-type="${type}">${ICONS[type]}<span><b>${type}</b> ${style.meaning}</span></div>`)
      .join("");
  // Each name in its constraint's colour through the style object: the page's
  // Content-Security-Policy refuses style attributes written in markup.
  for (const name of box.querySelectorAll<HTMLElement>(".hrc-legend-row b")) {
    name.style.color = CONSTRAINT_STYLE[name.textContent ?? ""]?.colour ?? "";
  }
  return box;
}
