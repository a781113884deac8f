/**
 * `constraint.reverse`: a constraint's two tasks change ends (t_a becomes t_b),
 * its arrow drawn the other way; revert swaps them back. The document's
 * `from` and `to` are read from the connection's ends, so nothing else moves.
 */

import type { CommandContext } from "diagram-js/lib/command/CommandStack";
import type { Connection, Element } from "diagram-js/lib/model/Types";

export interface ReverseConstraintContext extends CommandContext {
  connection: Connection;
}

export default class ReverseConstraintHandler {
  execute(context: ReverseConstraintContext): Element[] {
    return swap(context.connection);
  }

  revert(context: ReverseConstraintContext): Element[] {
    return swap(context.connection);
  }
}

function swap(connection: Connection): Element[] {
  const { source, target } = connection;
  // diagram-js' model keeps each shape's incoming and outgoing lists in step with these.
  connection.source = target;
  connection.target = source;
  connection.waypoints = [...(connection.waypoints ?? [])].reverse();
  return [connection, ...(source ? [source] : []), ...(target ? [target] : [])];
}
