/**
 * The hrc-pattern/1 document (shared/pattern-format.md) as the editor reads and
 * writes it. Reading checks the shape only, like the engine's read_pattern, and
 * keeps every key it does not know, so the layout and each task's
 * configuration travel with the model. The rules of the formal model are the
 * server's to check.
 */

import { jsonProblem } from "./json";

export const FORMAT = "hrc-pattern/1";
export const ACTOR_TYPES = ["cobot", "operator"] as const;
export const CONSTRAINT_TYPES = ["time", "space", "func"] as const;
export const PATTERN_NAMES = ["synchronized", "cooperation", "collaboration", "coexistence"] as const;

export type ActorType = (typeof ACTOR_TYPES)[number];
export type ConstraintType = (typeof CONSTRAINT_TYPES)[number];
export type PatternName = (typeof PATTERN_NAMES)[number];
export type Extra = Record<string, unknown>;

export interface Point {
  x: number;
  y: number;
}

export interface ActorData extends Extra {
  id: string;
  type: ActorType;
}

export interface PlaceData extends Extra {
  id: string;
  label?: string;
  tokens?: number;
}

export interface TransitionData extends Extra {
  id: string;
  label?: string;
  performer?: string;
}

export type Arc = [string, string];

export interface ProcessData extends Extra {
  id: string;
  workpiece?: string;
  actors: string[];
  places: PlaceData[];
  transitions: TransitionData[];
  arcs: Arc[];
}

export interface ConstraintData extends Extra {
  from: string;
  to: string;
  type: string;
}

export interface LaneLayout {
  actor: string;
  y: number;
  height: number;
}

export interface DocumentLayout extends Extra {
  lanes: LaneLayout[];
  width: number;
  height: number;
}

export interface PatternDocument extends Extra {
  format: typeof FORMAT;
  name?: string;
  declared_pattern?: PatternName;
  actors: ActorData[];
  processes: ProcessData[];
  constraints: ConstraintData[];
}

/** One shape problem: a message that names where it is, and the ids of the elements involved. */
export interface DocumentIssue {
  message: string;
  elements: string[];
}

export class DocumentError extends Error {
  constructor(readonly issues: DocumentIssue[]) {
    super(issues.map((issue) => issue.message).join(" "));
    this.name = "DocumentError";
  }
}

/** What a new process works on until the engineer names it (wpassign is total); the server's drafts say the same. */
export const DEFAULT_WORKPIECE = "workpiece";

/** A fresh, empty model: one net, no actors yet. */
export function emptyDocument(name = "New pattern"): PatternDocument {
  return {
    format: FORMAT,
    name,
    actors: [],
    processes: [{ id: "N", workpiece: DEFAULT_WORKPIECE, actors: [], places: [], transitions: [], arcs: [] }],
    constraints: [],
  };
}

/**
 * Reads a parsed document: a deep copy with every list present.
 * Throws DocumentError listing every shape problem it found.
 */
export function readDocument(value: unknown): PatternDocument {
  const reader = new Reader();
  const document = reader.document(value);
  if (document === null || reader.issues.length > 0) throw new DocumentError(reader.issues);
  return document;
}

/** The document as JSON-ready data (a deep copy, lists in their order). */
export function writeDocument(document: PatternDocument): PatternDocument {
  return structuredClone(document);
}

/** Parses JSON text into a document; a syntax error names its line and column. */
export function parseDocument(text: string): PatternDocument {
  let value: unknown;
  try {
    value = JSON.parse(text);
  } catch {
    const problem = jsonProblem(text);
    const at = problem ? `line ${problem.line}, column ${problem.column}` : "";
    const where = !problem ? "it cannot be read" : problem.found === "the end of the file" ? `it ends too early, at ${at}` : `unexpected ${problem.found} at ${at}`;
    throw new DocumentError([{ message: `The file is not JSON: ${where}.`, elements: [] }]);
  }
  return readDocument(value);
}

class Reader {
  readonly issues: DocumentIssue[] = [];

  fail(message: string, ...elements: string[]): void {
    this.issues.push({ message, elements });
  }

  object(value: unknown, where: string): Extra | null {
    if (isObject(value)) return value;
    this.fail(`${where} must be a JSON object, got ${kind(value)}.`);
    return null;
  }

  list<T>(data: Extra, key: string, where: string, read: (item: unknown, at: string) => T | null): T[] {
    const path = where ? `${where}.${key}` : key;
    const value = data[key] ?? [];
    if (!Array.isArray(value)) {
      this.fail(`${path} must be a list, got ${kind(value)}.`, ...idOf(data));
      return [];
    }
    return value.map((item, index) => read(item, `${path}[${index}]`)).filter((item): item is T => item !== null);
  }

  text(data: Extra, key: string, where: string, required = true): string | null | undefined {
    const value = data[key];
    if (value === undefined && !required) return undefined;
    if (typeof value === "string" && (value !== "" || !required)) return value;
    this.fail(`${name(where, data)}.${key} must be ${required ? "a non-empty string" : "a string"}, got ${kind(value)}.`, ...idOf(data));
    return null;
  }

  document(value: unknown): PatternDocument | null {
    const data = this.object(value, "The document");
    if (data === null) return null;
    if (data.format !== FORMAT) {
      this.fail(`The document must say "format": "${FORMAT}", got ${kind(data.format)}.`);
      return null;
    }
    this.text(data, "name", "The document", false);
    const declared = this.text(data, "declared_pattern", "The document", false);
    if (typeof declared === "string" && !(PATTERN_NAMES as readonly string[]).includes(declared)) {
      this.fail(`declared_pattern "${declared}" is not one of ${PATTERN_NAMES.join(", ")}.`);
    }
    const actors = this.list(data, "actors", "", (item, at) => this.actor(item, at));
    const processes = this.list(data, "processes", "", (item, at) => this.process(item, at));
    if (Array.isArray(data.processes) && data.processes.length === 0) {
      this.fail("The document has no process: a pattern needs at least one Petri net.");
    }
    const constraints = this.list(data, "constraints", "", (item, at) => this.constraint(item, at));
    return { ...structuredClone(data), format: FORMAT, actors, processes, constraints };
  }

  actor(value: unknown, where: string): ActorData | null {
    const data = this.object(value, where);
    if (data === null) return null;
    const id = this.text(data, "id", where);
    if (!(ACTOR_TYPES as readonly unknown[]).includes(data.type)) {
      this.fail(`${name(where, data)}.type must be "cobot" or "operator", got ${kind(data.type)}.`, ...idOf(data));
      return null;
    }
    return id ? (structuredClone(data) as ActorData) : null;
  }

  process(value: unknown, where: string): ProcessData | null {
    const data = this.object(value, where);
    if (data === null) return null;
    const before = this.issues.length;
    const id = this.text(data, "id", where);
    this.text(data, "workpiece", where, false);
    const at = name(where, data);
    const actors = this.list(data, "actors", at, (item, path) => this.actorRef(item, path));
    const places = this.list(data, "places", at, (item, path) => this.place(item, path));
    const transitions = this.list(data, "transitions", at, (item, path) => this.transition(item, path));
    const arcs = this.list(data, "arcs", at, (item, path) => this.arc(item, path));
    if (!id || this.issues.length > before) return null;
    return { ...structuredClone(data), id, actors, places, transitions, arcs };
  }

  actorRef(value: unknown, where: string): string | null {
    if (typeof value === "string" && value) return value;
    this.fail(`${where} must be an actor id (a non-empty string), got ${kind(value)}.`);
    return null;
  }

  place(value: unknown, where: string): PlaceData | null {
    const data = this.object(value, where);
    if (data === null) return null;
    const id = this.text(data, "id", where);
    this.text(data, "label", where, false);
    const tokens = data.tokens;
    if (tokens !== undefined && !(Number.isInteger(tokens) && (tokens as number) >= 0)) {
      this.fail(`${name(where, data)}.tokens must be a whole number ≥ 0, got ${kind(tokens)}.`, ...idOf(data));
      return null;
    }
    return id ? (structuredClone(data) as PlaceData) : null;
  }

  transition(value: unknown, where: string): TransitionData | null {
    const data = this.object(value, where);
    if (data === null) return null;
    const before = this.issues.length;
    const id = this.text(data, "id", where);
    this.text(data, "performer", where, false);
    this.text(data, "label", where, false);
    if (!id || this.issues.length > before) return null;
    return structuredClone(data) as TransitionData;
  }

  arc(value: unknown, where: string): Arc | null {
    if (Array.isArray(value) && value.length === 2 && value.every((end) => typeof end === "string" && end)) {
      return [value[0] as string, value[1] as string];
    }
    this.fail(`${where} must be a pair of node ids [from, to], got ${kind(value)}.`);
    return null;
  }

  constraint(value: unknown, where: string): ConstraintData | null {
    const data = this.object(value, where);
    if (data === null) return null;
    const before = this.issues.length;
    const from = this.text(data, "from", where);
    const to = this.text(data, "to", where);
    this.text(data, "type", where);
    if (this.issues.length > before) return null;
    return { ...structuredClone(data), from: from as string, to: to as string } as ConstraintData;
  }
}

export function isObject(value: unknown): value is Extra {
  return typeof value === "object" && value !== null && !Array.isArray(value);
}

/** `processes[0].places[2]` becomes `processes[0].places[2] (p3)`, a constraint `constraints[0] (to1 → tc2)`. */
function name(where: string, data: Extra): string {
  const id = data.id;
  if (typeof id === "string" && id) return `${where} (${id})`;
  if (typeof data.from === "string" && typeof data.to === "string") return `${where} (${data.from} → ${data.to})`;
  return where;
}

function idOf(data: Extra): string[] {
  return typeof data.id === "string" && data.id ? [data.id] : [];
}

/** A short description of a JSON value for messages: `nothing`, `the number 3`, `"abc"`. */
export function kind(value: unknown): string {
  if (value === undefined || value === null) return "nothing";
  if (typeof value === "boolean") return String(value);
  if (typeof value === "number") return `the number ${value}`;
  if (typeof value === "string") return `"${value.length <= 40 ? value : value.slice(0, 37) + "..."}"`;
  if (Array.isArray(value)) return `a list of ${value.length}`;
  return "an object";
}
