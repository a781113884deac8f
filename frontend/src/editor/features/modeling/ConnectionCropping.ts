/**
 * Connections end at the outline of their shapes, not at their centres, so
 * arrowheads show: each laid-out connection is cropped once per command.
 */

import CommandInterceptor from "diagram-js/lib/command/CommandInterceptor";
import type EventBus from "diagram-js/lib/core/EventBus";
import type { CommandContext } from "diagram-js/lib/command/CommandStack";
import type { Connection } from "diagram-js/lib/model/Types";

interface ConnectionDocking {
  getCroppedWaypoints(connection: Connection): { x: number; y: number }[];
}

export default class ConnectionCropping extends CommandInterceptor {
  static $inject = ["eventBus", "connectionDocking"];

  constructor(eventBus: EventBus, connectionDocking: ConnectionDocking) {
    super(eventBus);
    this.executed(["connection.layout", "connection.create"], (context: CommandContext) => {
      if (context.cropped || context.hints?.createElementsBehavior === false) return;
      const connection = context.connection as Connection;
      connection.waypoints = connectionDocking.getCroppedWaypoints(connection);
      context.cropped = true;
    }, true);
    this.reverted(["connection.layout"], (context: CommandContext) => {
      delete context.cropped;
    }, true);
  }
}
