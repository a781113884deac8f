/**
 * What each diagram element stands for (its businessObject) and small
 * questions about elements the features share. Node and lane objects hold
 * their document object in `data`; the shape's id is the document id.
 */

import type { Shape } from "diagram-js/lib/model/Types";

import type { ActorData, ConstraintData, Extra, PlaceData, TransitionData } from "../model/document";

export interface PlaceObject {
  kind: "place";
  process: string;
  data: PlaceData;
}

export interface TransitionObject {
  kind: "transition";
  process: string;
  /** A routing step (split, join) with no actor; fixed when the transition is made. */
  silent: boolean;
  data: TransitionData;
}

export interface LaneObject {
  kind: "lane";
  process: string | null;
  data: ActorData;
}

export interface ArcObject {
  kind: "arc";
}

export interface ConstraintObject {
  kind: "constraint";
  data: ConstraintData;
}

export interface RootObject {
  kind: "root";
  /** The document's own keys: name, declared_pattern and any the editor does not know. */
  data: Extra;
  /** Each process' keys but its nodes and arcs. */
  processes: Extra[];
  layoutExtra: Extra;
  width: number;
  height: number;
}

export type NodeObject = PlaceObject | TransitionObject;
export type PatternObject = NodeObject | LaneObject | ArcObject | ConstraintObject | RootObject;
export type Kind = PatternObject["kind"];

/** The part of didi's injector the features use. */
export interface Injector {
  get<T>(name: string, strict?: boolean): T;
}

export const PLACE_SIZE = 36;
export const TASK_SIZE = { width: 100, height: 60 };
export const SILENT_SIZE = { width: 20, height: 60 };
export const LANE_HEADER = 40;

/** Anything that may carry a pattern object: elements, roots, copy-paste descriptors. */
export type Element = { businessObject?: unknown } | undefined | null;

export function objectOf(element: Element): PatternObject | undefined {
  return element?.businessObject as PatternObject | undefined;
}

export function is(element: Element, kind: Kind): boolean {
  return objectOf(element)?.kind === kind;
}

export function isNode(element: Element): boolean {
  const kind = objectOf(element)?.kind;
  return kind === "place" || kind === "transition";
}

export function isLane(element: Element): boolean {
  return is(element, "lane");
}

/** A transition with a performer. */
export function isTask(element: Element): boolean {
  const object = objectOf(element);
  return object?.kind === "transition" && !object.silent;
}

export function isSilent(element: Element): boolean {
  const object = objectOf(element);
  return object?.kind === "transition" && object.silent;
}

export function isConstraint(element: Element): boolean {
  return is(element, "constraint");
}

export function isArc(element: Element): boolean {
  return is(element, "arc");
}

export function nodeObject(element: Element): NodeObject {
  return element?.businessObject as NodeObject;
}

export function laneObject(element: Element): LaneObject {
  return element?.businessObject as LaneObject;
}

export function performerOf(element: Element): string | undefined {
  const object = objectOf(element);
  return object?.kind === "transition" ? object.data.performer : undefined;
}

/** The lane whose band holds the height y; null outside every lane. */
/** The lanes among the elements, top to bottom. */
export function lanesTopDown(elements: Element[]): Shape[] {
  return (elements.filter(isLane) as Shape[]).sort((a, b) => a.y - b.y);
}

export function laneAt(lanes: Shape[], y: number): Shape | null {
  return lanes.find((lane) => y >= lane.y && y < lane.y + lane.height) ?? null;
}

export function centre(shape: Shape): { x: number; y: number } {
  return { x: shape.x + shape.width / 2, y: shape.y + shape.height / 2 };
}

export function sizeOf(object: NodeObject): { width: number; height: number } {
  if (object.kind === "place") return { width: PLACE_SIZE, height: PLACE_SIZE };
  return object.silent ? SILENT_SIZE : TASK_SIZE;
}
