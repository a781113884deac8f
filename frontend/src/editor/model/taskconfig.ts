/**
 * A task's `task` key (hrc/engine/taskconfig.py) as the properties panel edits
 * it: operator tasks have instructions and a form; cobot tasks run a program
 * step (program, number, workspace, poses) or a device call. Values may be
 * literals or case-data expressions (text starting with "=").
 */

import { type ActorType, type Extra, isObject } from "./document";

export type TaskKind = "operator" | "step" | "device";

/**
 * Device calls a cobot task can make, with their arguments in order: the engine's
 * taskconfig.DEVICE_CALLS as the editor page passes it; this copy serves pages without it.
 */
export const DEVICE_CALLS: Record<string, string[]> = {
  "linear-axis.move": ["direction", "duration_ms"],
  "part-detection.scan": [],
  "inspection.inspect": ["spot"],
  "display.show": ["text"],
  "recognition.gesture": ["gesture"],
  "recognition.face": [],
  "recognition.screws": ["expected"],
  "place-position.check": [],
  "place-position.wait": ["timeout_ms"],
};
/** How a space constraint's cobot makes way (its `interrupt` key), as the panel words it; pause is the default. */
export const INTERRUPT_MODES: Record<string, string> = { pause: "pauses", slow: "slows down" };
/** The `interrupt` modes a space constraint may have, by the kinds of its two actors (sorted,
 * joined by "+"), the default first: the server's taskconfig.SPACE_MODES. */
export const SPACE_MODES: Record<string, string[]> = {
  "cobot+operator": ["pause", "slow"],
  "cobot+cobot": ["wait", "pause"],
  "operator+operator": ["wait"],
};
/** How the panel asks for a space constraint's mode, and words each mode, per pair of actor kinds. */
export const SPACE_MODE_WORDS: Record<string, { question: string; modes: Record<string, string> }> = {
  "cobot+operator": { question: "While the operator is in the shared area, the cobot", modes: INTERRUPT_MODES },
  "cobot+cobot": {
    question: "When both cobots need the shared area",
    modes: { wait: "the later step waits for it", pause: "the running cobot pauses for the later step" },
  },
  "operator+operator": {
    question: "When both operators need the shared area",
    modes: { wait: "the second waits (the tablet tells them why)" },
  },
};

/** The key of SPACE_MODES for two actor kinds, in either order. */
export function actorPair(first: ActorType, second: ActorType): string {
  return [first, second].sort().join("+");
}
export const POSE_LENGTH = 6;
export const MAX_POSES = 2;
export const FIELD_TYPES = ["string", "integer", "number", "boolean"] as const;
export type FieldType = (typeof FIELD_TYPES)[number];

export interface FormField {
  name: string;
  type: FieldType;
  title: string;
  required: boolean;
}

export function isExpression(value: unknown): boolean {
  return typeof value === "string" && value.startsWith("=");
}

export function taskKind(task: Extra, actorType: ActorType | undefined): TaskKind {
  if (actorType !== "cobot") return "operator";
  return "device" in task ? "device" : "step";
}

/** The task with the cobot's work switched between a program step and a device call. */
export function withKind(task: Extra, kind: "step" | "device"): Extra {
  const { step, device, ...rest } = task;
  if (kind === "device") return { ...rest, device: isObject(device) ? device : { call: "part-detection.scan", args: {} } };
  return { ...rest, step: isObject(step) ? step : { number: 1, workspace: 0, poses: [] } };
}

/** A pose as a person types it: six numbers separated by commas or spaces, or an expression. */
export function parsePose(text: string): number[] | string {
  const trimmed = text.trim();
  if (isExpression(trimmed)) {
    if (trimmed.length === 1) throw new Error("An expression needs something after the =.");
    return trimmed;
  }
  const parts = trimmed.split(/[\s,;]+/).filter(Boolean);
  if (parts.length !== POSE_LENGTH) {
    throw new Error(`A pose is ${POSE_LENGTH} numbers (x, y, z, rx, ry, rz) or an expression starting with =; got ${parts.length} value${parts.length === 1 ? "" : "s"}.`);
  }
  return parts.map((part) => {
    const value = Number(part);
    if (!Number.isFinite(value)) throw new Error(`"${part}" is not a number.`);
    return value;
  });
}

export function formatPose(pose: unknown): string {
  if (typeof pose === "string" && isExpression(pose)) return pose;
  return Array.isArray(pose) ? pose.map((value) => String(value)).join(", ") : "";
}

/** Poses from the panel's lines (one pose a line); one "=…" line alone is an expression for the whole list. */
export function parsePoses(text: string): unknown {
  const lines = text.split("\n").map((line) => line.trim()).filter(Boolean);
  if (lines.length > MAX_POSES) throw new Error(`A step takes at most ${MAX_POSES} poses.`);
  return lines.map((line, index) => {
    try {
      return parsePose(line);
    } catch (error) {
      throw new Error(`Pose ${index + 1}: ${(error as Error).message}`, { cause: error });
    }
  });
}

export function formatPoses(poses: unknown): string {
  if (typeof poses === "string" && isExpression(poses)) return poses;
  return Array.isArray(poses) ? poses.map(formatPose).join("\n") : "";
}

/** A step's whole-number setting (number, workspace): a whole number ≥ 0 or an expression. */
export function parseWhole(text: string, what: string): number | string {
  const trimmed = text.trim();
  if (isExpression(trimmed)) return trimmed;
  const value = Number(trimmed);
  if (trimmed === "" || !Number.isInteger(value) || value < 0) {
    throw new Error(`The step's ${what} must be a whole number ≥ 0 or an expression starting with =.`);
  }
  return value;
}

export function fieldsOfForm(form: unknown): FormField[] {
  if (!isObject(form) || !isObject(form.properties)) return [];
  const required = Array.isArray(form.required) ? form.required : [];
  return Object.entries(form.properties).map(([name, schema]) => {
    const field = isObject(schema) ? schema : {};
    const type = (FIELD_TYPES as readonly unknown[]).includes(field.type) ? (field.type as FieldType) : "string";
    return { name, type, title: typeof field.title === "string" ? field.title : "", required: required.includes(name) };
  });
}

/** The JSON Schema object for a list of fields, keeping what each field's schema had beyond type and title. */
export function formOfFields(fields: FormField[], previous?: unknown): Extra | undefined {
  if (fields.length === 0) return undefined;
  const old = isObject(previous) && isObject(previous.properties) ? previous.properties : {};
  const names = new Set<string>();
  for (const field of fields) {
    if (!/^[A-Za-z_][A-Za-z0-9_]*$/.test(field.name)) throw new Error(`"${field.name}" is not a field name: use letters, digits and _.`);
    if (names.has(field.name)) throw new Error(`The form has two fields named ${field.name}.`);
    names.add(field.name);
  }
  const properties = Object.fromEntries(
    fields.map((field) => {
      const before = isObject(old[field.name]) ? (old[field.name] as Extra) : {};
      const schema: Extra = { ...before, type: field.type };
      if (field.title) schema.title = field.title;
      else delete schema.title;
      return [field.name, schema];
    }),
  );
  const required = fields.filter((field) => field.required).map((field) => field.name);
  const base = isObject(previous) ? previous : {};
  const form: Extra = { ...base, type: "object", properties };
  if (required.length) form.required = required;
  else delete form.required;
  return form;
}
