/**
 * The drawn elements an issue is about. An issue names ids: a node or lane is
 * drawn under its own id; a process is not drawn, so it stands for its lanes;
 * a constraint has no id of its own, so an issue about constraints (its code
 * starts with "constraint-") also stands for the constraints drawn between
 * the two tasks it names, from the first to the second.
 */

import type ElementRegistry from "diagram-js/lib/core/ElementRegistry";
import type { ConnectionLike, ElementLike } from "diagram-js/lib/core/Types";

import type { CheckIssue } from "../../api";
import { isConstraint, isLane, laneObject, objectOf, type RootObject } from "../../core/elements";

export function issueTargets(issue: CheckIssue, registry: ElementRegistry, root: ElementLike): ElementLike[] {
  const ids = [...new Set(issue.elements)];
  const processes = new Set(((objectOf(root) as RootObject | undefined)?.processes ?? []).map((process) => String(process.id)));
  const found: ElementLike[] = [];
  for (const id of ids) {
    const drawn = registry.get(id);
    if (drawn && drawn !== root) found.push(drawn);
    else if (processes.has(id)) found.push(...registry.filter((element) => isLane(element) && laneObject(element).process === id));
  }
  if (issue.code.startsWith("constraint-") && ids.length === 2) {
    const [from, to] = ids;
    found.push(...registry.filter((element) => isConstraint(element) && joins(element as ConnectionLike, from, to)));
  }
  return [...new Set(found)];
}

function joins(connection: ConnectionLike, from: string, to: string): boolean {
  return connection.source?.id === from && connection.target?.id === to;
}
