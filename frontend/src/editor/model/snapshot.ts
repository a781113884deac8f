/**
 * The document as the canvas holds it, and back: lanes, nodes with their
 * centres, arcs and constraints, each carrying its document object so keys the
 * editor does not know survive a round trip. Positions live in the document's
 * `layout` keys (a node's centre; lanes and size at the top level), so a saved
 * draft reopens as it was drawn.
 */

import {
  type ActorData,
  type ConstraintData,
  type DocumentLayout,
  DEFAULT_WORKPIECE,
  type Extra,
  FORMAT,
  isObject,
  type PatternDocument,
  type PlaceData,
  type ProcessData,
  type TransitionData,
} from "./document";

export type NodeKind = "place" | "transition";

export interface LaneItem {
  actor: ActorData;
  /** The process the actor is assigned to; null when none. */
  process: string | null;
  y: number;
  height: number;
}

export interface NodeItem {
  kind: NodeKind;
  process: string;
  data: PlaceData | TransitionData;
  /** The centre. */
  x: number;
  y: number;
}

export interface ArcItem {
  source: string;
  target: string;
}

export interface Snapshot {
  /** The document's own keys other than actors, processes, constraints and layout. */
  root: Extra;
  /** Each process' keys other than places, transitions and arcs. */
  processes: Extra[];
  lanes: LaneItem[];
  nodes: NodeItem[];
  arcs: ArcItem[];
  constraints: ConstraintData[];
  /** Top-level layout keys the editor does not know. */
  layoutExtra: Extra;
  width: number;
  height: number;
}

export const LANE_HEIGHT = 180;
export const MIN_WIDTH = 1000;

/** Whether every actor has a lane and every node a centre, so the document can be drawn as it is. */
export function hasLayout(document: PatternDocument): boolean {
  const layout = document.layout;
  if (!isObject(layout) || !Array.isArray(layout.lanes)) return false;
  const laned = new Set(layout.lanes.filter(isLane).map((lane) => lane.actor));
  if (!document.actors.every((actor) => laned.has(actor.id))) return false;
  return document.processes.every((process) =>
    [...process.places, ...process.transitions].every((node) => centreOf(node) !== null),
  );
}

export function toSnapshot(document: PatternDocument): Snapshot {
  const { actors, processes, constraints, layout, ...root } = structuredClone(document);
  const documentLayout = isObject(layout) ? layout : {};
  const laneLayout = new Map(
    (Array.isArray(documentLayout.lanes) ? documentLayout.lanes : []).filter(isLane).map((lane) => [lane.actor, lane]),
  );
  let nextY = Math.max(0, ...[...laneLayout.values()].map((lane) => lane.y + lane.height));
  const lanes = actors.map((actor): LaneItem => {
    const placed = laneLayout.get(actor.id);
    const lane = placed ?? { actor: actor.id, y: nextY, height: LANE_HEIGHT };
    if (!placed) nextY += LANE_HEIGHT;
    const process = processes.find((candidate) => candidate.actors.includes(actor.id));
    return { actor, process: process?.id ?? null, y: lane.y, height: lane.height };
  });
  const nodes: NodeItem[] = [];
  const arcs: ArcItem[] = [];
  for (const process of processes) {
    for (const [kind, list] of [["place", process.places], ["transition", process.transitions]] as const) {
      for (const data of list) {
        const centre = centreOf(data) ?? { x: 0, y: 0 };
        nodes.push({ kind, process: process.id, data, x: centre.x, y: centre.y });
      }
    }
    arcs.push(...process.arcs.map(([source, target]) => ({ source, target })));
  }
  const { lanes: _lanes, width, height, ...layoutExtra } = documentLayout;
  const extent = contentExtent(lanes, nodes);
  return {
    root,
    processes: processes.map(({ places: _p, transitions: _t, arcs: _a, ...meta }) => meta),
    lanes,
    nodes,
    arcs,
    constraints,
    layoutExtra,
    width: Math.max(typeof width === "number" ? width : 0, extent.width),
    height: Math.max(typeof height === "number" ? height : 0, extent.height),
  };
}

export function toDocument(snapshot: Snapshot): PatternDocument {
  const processIds = snapshot.processes.map((meta) => String(meta.id));
  const fallback = processIds[0] ?? "N";
  const processes: ProcessData[] = (snapshot.processes.length ? snapshot.processes : [{ id: "N", workpiece: DEFAULT_WORKPIECE, actors: [] }]).map(
    (meta) => ({
      ...structuredClone(meta),
      id: String(meta.id),
      actors: processActors(meta, snapshot.lanes),
      places: [],
      transitions: [],
      arcs: [],
    }),
  );
  const byId = new Map(processes.map((process) => [process.id, process]));
  const processOfNode = new Map<string, ProcessData>();
  const fallbackProcess = byId.get(fallback) ?? processes[0];
  for (const node of snapshot.nodes) {
    const process = byId.get(node.process) ?? fallbackProcess;
    const data = { ...structuredClone(node.data), layout: withCentre(node.data.layout, node) };
    if (node.kind === "place") process.places.push(data);
    else process.transitions.push(data);
    processOfNode.set(node.data.id, process);
  }
  for (const arc of snapshot.arcs) {
    const process = processOfNode.get(arc.source) ?? processOfNode.get(arc.target) ?? processes[0];
    process.arcs.push([arc.source, arc.target]);
  }
  const layout: DocumentLayout = {
    ...structuredClone(snapshot.layoutExtra),
    lanes: snapshot.lanes.map((lane) => ({ actor: lane.actor.id, y: Math.round(lane.y), height: Math.round(lane.height) })),
    width: Math.round(snapshot.width),
    height: Math.round(snapshot.height),
  };
  return {
    ...structuredClone(snapshot.root),
    format: FORMAT,
    actors: snapshot.lanes.map((lane) => structuredClone(lane.actor)),
    processes,
    constraints: structuredClone(snapshot.constraints),
    layout,
  };
}

/**
 * The actors a process lists: those it listed before whose lane still says
 * this process (or that have no lane: kept as written), then new ones.
 */
function processActors(meta: Extra, lanes: LaneItem[]): string[] {
  const id = String(meta.id);
  const laneOf = new Map(lanes.map((lane) => [lane.actor.id, lane]));
  const listed = (Array.isArray(meta.actors) ? meta.actors : []).filter((actor): actor is string => {
    if (typeof actor !== "string") return false;
    const lane = laneOf.get(actor);
    return lane === undefined || lane.process === id;
  });
  const added = lanes.filter((lane) => lane.process === id && !listed.includes(lane.actor.id));
  return [...listed, ...added.map((lane) => lane.actor.id)];
}

function withCentre(previous: unknown, centre: { x: number; y: number }): Extra {
  return { ...(isObject(previous) ? previous : {}), x: Math.round(centre.x), y: Math.round(centre.y) };
}

function centreOf(node: Extra): { x: number; y: number } | null {
  const layout = node.layout;
  if (!isObject(layout) || typeof layout.x !== "number" || typeof layout.y !== "number") return null;
  if (!Number.isFinite(layout.x) || !Number.isFinite(layout.y)) return null;
  return { x: layout.x, y: layout.y };
}

function isLane(value: unknown): value is { actor: string; y: number; height: number } {
  return (
    isObject(value) &&
    typeof value.actor === "string" &&
    typeof value.y === "number" &&
    typeof value.height === "number" &&
    value.height > 0
  );
}

function contentExtent(lanes: LaneItem[], nodes: NodeItem[]): { width: number; height: number } {
  const right = Math.max(0, ...nodes.map((node) => node.x + 120));
  const bottom = Math.max(0, ...lanes.map((lane) => lane.y + lane.height), ...nodes.map((node) => node.y + 60));
  return { width: Math.max(MIN_WIDTH, right), height: bottom };
}
