/**
 * What the hrc-pattern/1 format forbids, said before anything is drawn. Each
 * function returns why an edit is refused, or null when it is allowed; the
 * editor's rule provider asks them and shows the reason. The server's engine
 * still has the final word on the whole model.
 */

import { CONSTRAINT_TYPES } from "./document";

export interface NodeInfo {
  id: string;
  kind: "place" | "transition";
  /** The actor of a task; undefined for a place or a silent transition. */
  performer?: string;
  process: string;
}

export interface ConstraintInfo {
  from: string;
  to: string;
  type: string;
}

export function arcRefusal(source: NodeInfo, target: NodeInfo, arcs: { source: string; target: string }[]): string | null {
  if (source.kind === "place" && target.kind === "place") {
    return `An arc cannot join two places (${source.id} → ${target.id}): put a transition between them.`;
  }
  if (source.kind === "transition" && target.kind === "transition") {
    return `An arc cannot join two transitions (${source.id} → ${target.id}): put a place between them.`;
  }
  if (source.process !== target.process) {
    return `${source.id} is in net ${source.process} and ${target.id} in net ${target.process}: an arc stays inside one net.`;
  }
  if (arcs.some((arc) => arc.source === source.id && arc.target === target.id)) {
    return `There is already an arc from ${source.id} to ${target.id}.`;
  }
  return null;
}

export function constraintRefusal(
  source: NodeInfo,
  target: NodeInfo,
  type: string,
  constraints: ConstraintInfo[],
): string | null {
  if (!(CONSTRAINT_TYPES as readonly string[]).includes(type)) {
    return `Unknown constraint type "${type}": use time, space or func.`;
  }
  for (const end of [source, target]) {
    if (end.kind === "place") return `A constraint joins two tasks; ${end.id} is a place.`;
    if (!end.performer) {
      return `${end.id} is a silent transition: only a task (a transition with an actor) can be constrained.`;
    }
  }
  if (source.id === target.id) return `A constraint joins two different tasks; ${source.id} cannot constrain itself.`;
  if (source.performer === target.performer) {
    return `${source.id} and ${target.id} are both tasks of ${source.performer}: a constraint joins tasks of different actors.`;
  }
  const drawn = constraints.find((c) => c.from === source.id && c.to === target.id);
  if (drawn?.type === type) return `There is already a ${type} constraint from ${source.id} to ${target.id}.`;
  if (drawn) {
    return `There is already a ${drawn.type} constraint from ${source.id} to ${target.id}: an ordered pair of tasks has one constraint type (change that one's type instead).`;
  }
  return null;
}

/** Why a task cannot be performed by `actor` (moved into its lane, or reassigned), or null. */
export function performerRefusal(task: string, actor: string | null, constraints: ConstraintInfo[], performerOf: (task: string) => string | undefined): string | null {
  if (actor === null) return `A task belongs to an actor: put ${task} inside an actor's lane.`;
  for (const constraint of constraints) {
    const other = constraint.from === task ? constraint.to : constraint.to === task ? constraint.from : null;
    if (other !== null && performerOf(other) === actor) {
      return `${task} cannot become a task of ${actor}: its ${constraint.type} constraint with ${other} (a task of ${actor}) must join tasks of different actors.`;
    }
  }
  return null;
}

export function newTaskRefusal(actor: string | null, laneCount: number): string | null {
  if (actor !== null) return null;
  if (laneCount === 0) return "Add an operator or cobot lane first: every task belongs to an actor.";
  return "A task belongs to an actor: drop it inside an actor's lane.";
}

export function laneRemovalRefusal(actor: string, tasks: string[]): string | null {
  if (tasks.length === 0) return null;
  const listed = tasks.slice(0, 4).join(", ") + (tasks.length > 4 ? ", …" : "");
  return `The lane of ${actor} still holds ${tasks.length === 1 ? "task" : "tasks"} ${listed}: delete them or move them to another lane first.`;
}

export const LANE_MOVE_REFUSAL = "Lanes stay where they are: move the places and transitions inside them instead.";
export const LANE_CONNECT_REFUSAL = "Arcs and constraints join places and transitions, not lanes.";
