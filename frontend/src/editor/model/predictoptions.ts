/**
 * The Predict panel's options as the engineer types them, and what the server is sent
 * (PredictOptionsSerializer, hrc/engine/durations.py's duration_from_dict): the cases, how
 * many at once, the seed, the persons of each operator lane and each task's given time. Each
 * problem is keyed by the field it is about, for the panel to show beside it.
 */

import type { GivenTime, PredictOptions, TaskDuration } from "./prediction";

/** How a task's time is given; "" is not given: measured, the program's or the default. */
export type TimeKind = "" | "fixed" | "triangular" | "lognormal";

/** A task's time as typed: its kind and the text of each of its fields. */
export interface TimeEntry {
  kind: TimeKind;
  values: Record<string, string>;
}

export const TIME_KINDS: [TimeKind, string][] = [
  ["", "Not given"],
  ["fixed", "Fixed"],
  ["triangular", "Triangular"],
  ["lognormal", "Lognormal"],
];

/** The fields of each kind of time, with their labels. */
export const TIME_FIELDS: Record<Exclude<TimeKind, "">, [string, string][]> = {
  fixed: [["seconds", "Seconds"]],
  triangular: [
    ["low", "Low (s)"],
    ["mode", "Mode (s)"],
    ["high", "High (s)"],
  ],
  lognormal: [
    ["median", "Median (s)"],
    ["p90", "p90 (s)"],
  ],
};

/** Everything the panel's fields hold, as text. */
export interface OptionsInput {
  cases: string;
  parallel: string;
  seed: string;
  /** Operator actor id → persons in its team. */
  people: Record<string, string>;
  /** Task id → its time; tasks not here have none given. */
  times: Record<string, TimeEntry>;
}

/** Field key → what is wrong with it; see `peopleKey` and `timeKey`. */
export type Problems = Record<string, string>;

export function peopleKey(actor: string): string {
  return `people:${actor}`;
}

export function timeKey(task: string, field: string): string {
  return `time:${task}:${field}`;
}

/**
 * The options to send, and the problems that keep them from being sent (none: send them).
 * The counts are checked for being whole numbers only: their ranges are the server's to
 * judge, in its words. A task whose time is not given is left out.
 */
export function readOptions(input: OptionsInput): { options: PredictOptions; problems: Problems } {
  const problems: Problems = {};
  const whole = (key: string, name: string, text: string): number => {
    const value = wholeNumber(text);
    if (value === null) problems[key] = `${name} must be a whole number.`;
    return value ?? 0;
  };
  const people: Record<string, number> = {};
  for (const [actor, text] of Object.entries(input.people)) people[actor] = whole(peopleKey(actor), `Persons in ${actor}`, text);
  const durations: Record<string, GivenTime> = {};
  for (const [task, entry] of Object.entries(input.times)) {
    const { time, problems: wrong } = readTime(entry);
    for (const [field, message] of Object.entries(wrong)) problems[timeKey(task, field)] = message;
    if (time) durations[task] = time;
  }
  const options: PredictOptions = {
    cases: whole("cases", "Cases", input.cases),
    parallel: whole("parallel", "Cases at once", input.parallel),
    seed: whole("seed", "Seed", input.seed),
    people,
    durations,
  };
  return { options, problems };
}

/** The time an entry gives (null when not given or wrong) and its problems by field. */
export function readTime(entry: TimeEntry): { time: GivenTime | null; problems: Problems } {
  if (entry.kind === "") return { time: null, problems: {} };
  const problems: Problems = {};
  const seconds: Record<string, number> = {};
  for (const [field] of TIME_FIELDS[entry.kind]) {
    const value = secondsOf(entry.values[field] ?? "");
    if (typeof value === "string") problems[field] = value;
    else seconds[field] = value;
  }
  if (Object.keys(problems).length) return { time: null, problems };
  const problem = orderProblem(entry.kind, seconds);
  if (problem) return { time: null, problems: { [problem[0]]: problem[1] } };
  return { time: { kind: entry.kind, ...seconds } as GivenTime, problems: {} };
}

/** Where a prediction took a task's time from, in words: "Measured: lognormal, median 12 s (30 runs)". */
export function timeSource(duration: TaskDuration): string {
  const source = { given: "Given by you", measured: "Measured", program: "Program", assumed: "Assumed" }[duration.source];
  return `${source}: ${duration.describe}`;
}

/** A count's number; null unless the text is a whole number. */
function wholeNumber(text: string): number | null {
  const value = text.trim() === "" ? Number.NaN : Number(text);
  return Number.isInteger(value) ? value : null;
}

/** A time in seconds, or what is wrong with the text. */
function secondsOf(text: string): number | string {
  if (text.trim() === "") return "Give a time in seconds.";
  const value = Number(text);
  if (!Number.isFinite(value)) return "A time is a number of seconds.";
  if (value < 0) return "A time cannot be negative.";
  return value;
}

/** The field whose value is out of order with the others, and why; null when they are in order. */
function orderProblem(kind: Exclude<TimeKind, "">, seconds: Record<string, number>): [string, string] | null {
  if (kind === "triangular") {
    if (seconds.low > seconds.high) return ["high", "High must not be below low."];
    if (seconds.mode < seconds.low || seconds.mode > seconds.high) return ["mode", "Mode must lie between low and high."];
  }
  if (kind === "lognormal") {
    if (seconds.median <= 0) return ["median", "The median must be above 0 s."];
    if (seconds.p90 < seconds.median) return ["p90", "p90 must not be below the median."];
  }
  return null;
}
