/**
 * A lane answers the mouse only on its outline and its header band, so a
 * press inside the lane reaches the canvas: to pan, lasso or drop there.
 */

import type EventBus from "diagram-js/lib/core/EventBus";
import type InteractionEvents from "diagram-js/lib/features/interaction-events/InteractionEvents";
import type { Shape } from "diagram-js/lib/model/Types";

import { isLane, LANE_HEADER } from "../../core/elements";

export default class LaneHits {
  static $inject = ["eventBus", "interactionEvents"];

  constructor(eventBus: EventBus, interactionEvents: InteractionEvents) {
    const draw = (event: { element: Shape; gfx: SVGElement }) => {
      if (!isLane(event.element)) return;
      interactionEvents.removeHits(event.gfx);
      interactionEvents.createBoxHit(event.gfx, "stroke", { width: event.element.width, height: event.element.height });
      interactionEvents.createBoxHit(event.gfx, "all", { width: LANE_HEADER, height: event.element.height });
      return true;
    };
    eventBus.on("interactionEvents.createHit", 1500, draw);
    eventBus.on("interactionEvents.updateHit", 1500, draw);
  }
}
