/** Actors as horizontal lanes: who performs a task follows the lane it is in. */

import InteractionEventsModule from "diagram-js/lib/features/interaction-events";

import LaneBehavior from "./LaneBehavior";
import LaneHits from "./LaneHits";

export default {
  __depends__: [InteractionEventsModule],
  __init__: ["laneBehavior", "laneHits"],
  laneBehavior: ["type", LaneBehavior],
  laneHits: ["type", LaneHits],
};
